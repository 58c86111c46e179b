//! Metering from the rendered frame, as engines' auto-exposure does: the
//! log-average luminance of the pixels the mesh covers (the HDR image's alpha),
//! L̄ = exp(mean log(δ + L)) (Reinhard, Stark, Shirley & Ferwerda 2002, eq. 1),
//! mapped to the key 0.18 of a normal-key scene (ibid. §3.1): exposure =
//! log2(0.18 / L̄) EV. On the GPU two timed passes, `meter` (one partial sum
//! per 32 × 32 tile) and `meter_reduce` (one workgroup), write the EV into a
//! buffer the tone-map pass reads in the same frame; `render/` reads it back
//! afterwards. [`exposure`] is the CPU reference.

use crate::error::Result;
use crate::gpu::{Buffer, MemoryLocation, Pipeline, Pipelines, Sampler};
use crate::graph::{Access, BufferHandle, Graph, ImageHandle, Imported};
use crate::scene::texture::LUMINANCE;
use ash::vk;
use std::sync::Arc;

/// Reinhard et al. 2002 §3.1: "the key … 0.18 on a scale from zero to one".
pub const KEY: f32 = 0.18;
/// δ of Reinhard et al.'s eq. 1, "a small value" that keeps black pixels'
/// logarithm finite; 1e-4 is 11 stops under the key.
pub const DELTA: f32 = 1e-4;
/// Alpha above which a pixel is the mesh's.
pub const COVERED: f32 = 0.5;
/// Bytes of the result: EV, L̄, pixels metered, 0 (f32 each).
pub const RESULT_BYTES: u64 = 16;
/// Side of the tiles `meter` sums (meter.comp: 8 × 8 threads of 4 × 4 pixels).
const TILE: u32 = 32;

/// What a metering found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metered {
    /// log2(KEY / L̄); 0 when no pixel was covered.
    pub ev: f32,
    /// The log-average luminance L̄.
    pub log_average: f32,
    pub pixels: u32,
}

impl Metered {
    /// From the log-luminance sum over `pixels` pixels.
    fn of(log_sum: f64, pixels: u64) -> Metered {
        if pixels == 0 {
            return Metered {
                ev: 0.0,
                log_average: 0.0,
                pixels: 0,
            };
        }
        let log_average = (log_sum / pixels as f64).exp() as f32;
        Metered {
            ev: (KEY / log_average).log2(),
            log_average,
            pixels: pixels as u32,
        }
    }

    /// What a metering of an image × 2^`pre_ev` says of the image itself.
    pub fn pre_exposed_by(self, pre_ev: f32) -> Metered {
        Metered {
            ev: self.ev + pre_ev,
            log_average: self.log_average * (-pre_ev).exp2(),
            ..self
        }
    }

    /// The GPU's result buffer as read back.
    pub fn from_bytes(bytes: &[u8]) -> Metered {
        let v: &[f32] = bytemuck::cast_slice(&bytes[..RESULT_BYTES as usize]);
        Metered {
            ev: v[0],
            log_average: v[1],
            pixels: v[2] as u32,
        }
    }
}

/// The CPU reference: meters linear RGBA (alpha = coverage).
pub fn exposure(rgba: &[f32]) -> Metered {
    let (mut sum, mut n) = (0.0f64, 0u64);
    for p in rgba.chunks_exact(4).filter(|p| p[3] > COVERED) {
        let l = glam::Vec3::from_slice(&p[..3]).dot(LUMINANCE);
        sum += f64::from(DELTA + l.max(0.0)).ln();
        n += 1;
    }
    Metered::of(sum, n)
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct TilePush {
    luminance: [f32; 3],
    delta: f32,
    covered: f32,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ReducePush {
    tiles: u32,
    key: f32,
}

pub struct Meter {
    tiles: Arc<Pipeline>,
    reduce: Arc<Pipeline>,
    sampler: Arc<Sampler>,
    /// (log sum, pixels) per tile.
    partials: Arc<Buffer>,
    /// [`RESULT_BYTES`]: what the tone map reads.
    result: Arc<Buffer>,
}

/// Tiles of an image of `width` × `height`.
fn tiles_of(width: u32, height: u32) -> [u32; 2] {
    [width.div_ceil(TILE), height.div_ceil(TILE)]
}

impl Meter {
    /// For images of any size the device allows: a screen view at any window
    /// size, a UV-space view at its own resolution (the viewer meters both).
    pub fn new(pipelines: &Pipelines, sampler: Arc<Sampler>) -> Result<Self> {
        let ctx = pipelines.ctx();
        let max = ctx.info.max_image_dimension_2d;
        let [x, y] = tiles_of(max, max);
        let tile_count = u64::from(x) * u64::from(y);
        let buffer = |name: &str, size: u64, extra| {
            Buffer::new(
                ctx,
                name,
                size,
                vk::BufferUsageFlags::STORAGE_BUFFER | extra,
                MemoryLocation::GpuOnly,
            )
            .map(Arc::new)
        };
        Ok(Self {
            tiles: pipelines.compute("meter.comp", &[])?,
            reduce: pipelines.compute("meter_reduce.comp", &[])?,
            sampler,
            partials: buffer(
                "meter partials",
                tile_count * 8,
                vk::BufferUsageFlags::empty(),
            )?,
            result: buffer("exposure", RESULT_BYTES, vk::BufferUsageFlags::TRANSFER_SRC)?,
        })
    }

    /// The result buffer as the frame's passes see it: last read by the
    /// previous frame's readback.
    pub fn result(&self, g: &mut Graph) -> BufferHandle {
        g.import_buffer(
            "exposure",
            Imported::Buffer(self.result.clone()),
            Some(Access::TransferSrc),
            None,
        )
    }

    /// Meters `hdr` (passes `meter`, `meter_reduce`); returns the result, written.
    pub fn pass(&self, g: &mut Graph, hdr: &ImageHandle) -> BufferHandle {
        let tiles_xy = tiles_of(hdr.desc.width, hdr.desc.height);
        let mut result = self.result(g);
        let mut partials = g.import_buffer(
            "meter partials",
            Imported::Buffer(self.partials.clone()),
            Some(Access::ComputeBufferRead),
            None,
        );
        g.simple_pass("meter", &self.tiles)
            .tag(super::TAG)
            .sample(hdr, &self.sampler)
            .write_buffer(&mut partials)
            .constants(&TilePush {
                luminance: LUMINANCE.to_array(),
                delta: DELTA,
                covered: COVERED,
            })
            .dispatch_groups([tiles_xy[0], tiles_xy[1], 1]);
        g.simple_pass("meter_reduce", &self.reduce)
            .tag(super::TAG)
            .read_buffer(&partials)
            .write_buffer(&mut result)
            .constants(&ReducePush {
                tiles: tiles_xy[0] * tiles_xy[1],
                key: KEY,
            })
            .dispatch_groups([1, 1, 1]);
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_uniform_grey_meets_the_key() {
        // Every covered pixel at L: L̄ = δ + L, EV = log2(0.18 / L̄); uncovered
        // pixels do not count.
        let mut rgba = [0.5f32, 0.5, 0.5, 1.0].repeat(10);
        rgba.extend([100.0, 100.0, 100.0, 0.0]);
        let m = exposure(&rgba);
        assert_eq!(m.pixels, 10);
        assert!((m.log_average - 0.5001).abs() < 1e-6, "{m:?}");
        assert!((m.ev - (0.18f32 / 0.5001).log2()).abs() < 1e-6, "{m:?}");
        // The log-average of 0.1 and 1 is √0.1 (geometric mean).
        let m = exposure(&[0.1, 0.1, 0.1, 1.0, 1.0, 1.0, 1.0, 1.0]);
        assert!(
            (m.log_average - (0.1001f32 * 1.0001).sqrt()).abs() < 1e-6,
            "{m:?}"
        );
        assert_eq!(exposure(&[1.0, 1.0, 1.0, 0.0]).ev, 0.0);
    }
}
