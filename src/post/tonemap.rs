//! Exposure, the tone curve and the output transfer function into an 8-bit
//! target (docs/design/post.md). The CPU functions here are written from the published
//! formulas and are the reference the pass is tested against; [`encode8`] also
//! encodes images read back as floats (UV-space views, the CPU reference).
//!
//! - `linear`: clip to [0, 1].
//! - `aces`: Narkowicz, "ACES Filmic Tone Mapping Curve" (2016-01-06,
//!   knarkowicz.wordpress.com): x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14),
//!   clipped, per channel; his fit of the ACES RRT + sRGB ODT (with its 0.6
//!   pre-exposure folded in).
//! - `neutral`: Khronos PBR Neutral (Khronos Group, 2024; KhronosGroup/ToneMapping),
//!   start of compression 0.8 − 0.04, desaturation 0.15.
//! - transfer: the sRGB curve of IEC 61966-2-1 or a pure power.

use super::{Display, Exposure};
use crate::error::Result;
use crate::gpu::{GraphicsDesc, Pipeline, Pipelines, Sampler};
use crate::graph::{BufferHandle, Graph, ImageHandle, LoadOp};
use crate::scene::file::{Gamma, ToneCurve};
use ash::vk;
use std::sync::Arc;

pub const LDR_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;

/// Push constants of tonemap.frag.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct TonemapPush {
    /// rgb: Display::background; a: 0.
    background: [f32; 4],
    /// EV, when not metered.
    exposure: f32,
    /// 0: the sRGB curve; else encoded = linear^(1/gamma).
    gamma: f32,
    /// ToneCurve as 0, 1, 2.
    curve: u32,
    /// 1: read the exposure from the meter's buffer.
    metered: u32,
}

fn gamma_param(gamma: Gamma) -> f32 {
    match gamma {
        Gamma::Srgb => 0.0,
        Gamma::Power(g) => g,
    }
}

/// Narkowicz's ACES fit, one channel.
fn aces(x: f32) -> f32 {
    let (a, b, c, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
    ((x * (a * x + b)) / (x * (c * x + d) + e)).clamp(0.0, 1.0)
}

/// Khronos PBR Neutral, as its specification's reference code.
fn neutral(rgb: [f32; 3]) -> [f32; 3] {
    const START_COMPRESSION: f32 = 0.8 - 0.04;
    const DESATURATION: f32 = 0.15;
    let x = rgb[0].min(rgb[1]).min(rgb[2]);
    let offset = if x < 0.08 { x - 6.25 * x * x } else { 0.04 };
    let c = rgb.map(|v| v - offset);
    let peak = c[0].max(c[1]).max(c[2]);
    if peak < START_COMPRESSION {
        return c;
    }
    let d = 1.0 - START_COMPRESSION;
    let new_peak = 1.0 - d * d / (peak + d - START_COMPRESSION);
    let g = 1.0 - 1.0 / (DESATURATION * (peak - new_peak) + 1.0);
    c.map(|v| v * new_peak / peak * (1.0 - g) + new_peak * g)
}

/// Exposed linear RGB to display-linear RGB (not yet clipped for `linear`).
pub fn tone(rgb: [f32; 3], curve: ToneCurve) -> [f32; 3] {
    match curve {
        ToneCurve::Linear => rgb,
        ToneCurve::Aces => rgb.map(aces),
        ToneCurve::Neutral => neutral(rgb),
    }
}

/// One channel, display-linear to encoded in [0, 1].
pub fn encode(c: f32, gamma: Gamma) -> f32 {
    let c = c.clamp(0.0, 1.0);
    match gamma {
        // IEC 61966-2-1.
        Gamma::Srgb if c <= 0.003_130_8 => 12.92 * c,
        Gamma::Srgb => 1.055 * c.powf(1.0 / 2.4) - 0.055,
        Gamma::Power(g) => c.powf(1.0 / g),
    }
}

/// Linear RGBA → 8-bit: × 2^exposure, the tone curve, the background where
/// alpha (coverage) is below 1, the transfer function; alpha 255.
pub fn encode8(rgba: &[f32], exposure: f32, display: &Display) -> Vec<u8> {
    let scale = exposure.exp2();
    rgba.chunks_exact(4)
        .flat_map(|p| {
            let toned = tone([p[0], p[1], p[2]].map(|c| c * scale), display.curve);
            let uncovered = 1.0 - p[3].clamp(0.0, 1.0);
            let q = |i: usize| {
                let c = toned[i] + uncovered * display.background[i];
                (encode(c, display.gamma) * 255.0).round() as u8
            };
            [q(0), q(1), q(2), 255]
        })
        .collect()
}

pub struct Tonemap {
    pipeline: Arc<Pipeline>,
    sampler: Arc<Sampler>,
}

impl Tonemap {
    pub fn new(pipelines: &Pipelines, sampler: Arc<Sampler>) -> Result<Self> {
        let pipeline =
            pipelines.graphics(&GraphicsDesc::fullscreen("tonemap.frag", &[LDR_FORMAT]))?;
        Ok(Self { pipeline, sampler })
    }

    /// `hdr` exposed (given, or `metered`'s EV: post::meter), toned and
    /// encoded for `display` into `ldr`.
    pub fn pass(
        &self,
        g: &mut Graph,
        hdr: &ImageHandle,
        metered: &BufferHandle,
        ldr: &mut ImageHandle,
        exposure: Exposure,
        display: &Display,
    ) {
        let [r, gr, b] = display.background;
        g.simple_pass("tonemap", &self.pipeline)
            .tag(super::TAG)
            .sample(hdr, &self.sampler)
            .read_buffer(metered)
            .color(ldr, LoadOp::DontCare)
            .constants(&TonemapPush {
                background: [r, gr, b, 0.0],
                exposure: match exposure {
                    Exposure::Given(ev) => ev,
                    Exposure::Metered => 0.0,
                },
                gamma: gamma_param(display.gamma),
                curve: display.curve as u32,
                metered: u32::from(exposure == Exposure::Metered),
            })
            .draw(3);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encodings_match_their_definitions() {
        // IEC 61966-2-1 reference points: 0.5 → 0.7354, 0.0031308 on the knee.
        assert!((encode(0.5, Gamma::Srgb) - 0.735_36).abs() < 1e-4);
        assert!((encode(0.003_130_8, Gamma::Srgb) - 0.040_45).abs() < 1e-4);
        assert_eq!(encode(0.25, Gamma::Power(2.0)), 0.5);
        assert_eq!(encode(0.25, Gamma::Power(1.0)), 0.25);
        assert!((encode(7.0, Gamma::Srgb) - 1.0).abs() < 1e-6);
        // Exposure +1 EV doubles before encoding; uncovered pixels get the background.
        let display = Display::data([0.0, 0.5, 0.0]);
        assert_eq!(
            encode8(&[0.125, 0.0, 1.0, 1.0, 0.0, 0.0, 0.25, 0.0], 1.0, &display),
            [64, 0, 255, 255, 0, 128, 128, 255]
        );
    }

    #[test]
    fn curves_pass_their_published_points() {
        // Narkowicz: f(0) = 0; f(0.18) = 0.2669 (by the formula:
        // 0.18·(0.4518 + 0.03) / (0.18·(0.4374 + 0.59) + 0.14) = 0.08672/0.32493);
        // f → 2.51/2.43 > 1, clipped to 1.
        assert_eq!(aces(0.0), 0.0);
        assert!((aces(0.18) - 0.266_9).abs() < 1e-4, "{}", aces(0.18));
        assert_eq!(aces(1e4), 1.0);
        // Neutral: identity minus the toe offset below 0.76 (a mid grey
        // 0.18 → 0.14); white 1 is 0.96 after the 0.04 offset and compresses
        // to 1 − 0.24²/(0.96 + 0.24 − 0.76) = 0.8691; peaks never exceed 1.
        let grey = neutral([0.18; 3]);
        assert!((grey[0] - 0.14).abs() < 1e-6, "{grey:?}");
        let white = neutral([1.0; 3]);
        assert!((white[0] - 0.869_09).abs() < 1e-5, "{white:?}");
        assert!(neutral([100.0, 1.0, 0.5]).iter().all(|&c| c <= 1.0));
        // Hue kept below the knee: a dim red stays red.
        let red = neutral([0.5, 0.1, 0.1]);
        assert!(red[0] > red[1] && (red[1] - red[2]).abs() < 1e-6, "{red:?}");
        assert_eq!(tone([2.0, 0.5, 0.0], ToneCurve::Linear), [2.0, 0.5, 0.0]);
    }
}
