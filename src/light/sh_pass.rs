//! SH projection of the environment on the GPU (the paper's eq. 10; Ramamoorthi &
//! Hanrahan 2001), as two timed graph passes: `sh_project` (one workgroup per
//! row) and `sh_reduce` (sum, rotate, scale). `light::sh::project` is the CPU
//! reference it is tested against.

use super::sh::{self, Sh9};
use crate::error::Result;
use crate::frame_inputs::upload_env;
use crate::gpu::{Buffer, Context, Image, MemoryLocation, Pipeline, Pipelines, Sampler};
use crate::graph::upload::{upload_buffer, Readback};
use crate::graph::{Access, BufferHandle, Executor, Graph, Imported};
use crate::scene::env::EnvMap;
use crate::timing::FrameTiming;
use ash::vk;
use glam::{Mat3, Vec3};
use std::sync::Arc;

/// The 9×9 block-diagonal matrix M with rotate_y(L, degrees) = M·L (row-major).
pub fn rotation_matrix(degrees: f32) -> [f32; 81] {
    let r = Mat3::from_rotation_y(degrees.to_radians());
    let mut m = [0.0; 81];
    for j in 0..9 {
        let mut e: Sh9 = [Vec3::ZERO; 9];
        e[j] = Vec3::X;
        for (i, c) in sh::rotate(&e, r).iter().enumerate() {
            m[i * 9 + j] = c.x;
        }
    }
    m
}

pub struct ShPasses {
    project: Arc<Pipeline>,
    reduce: Arc<Pipeline>,
    sampler: Arc<Sampler>,
}

/// Buffers of one environment's projection, reused frame after frame.
pub struct ShBuffers {
    partials: Arc<Buffer>,
    transform: Arc<Buffer>,
    /// Nine vec4 (rgb, 0): rotated and scaled coefficients.
    pub coefficients: Arc<Buffer>,
    rows: u32,
    /// What the transform was made from (light::lighting::key): the
    /// coefficients are kept for it.
    key: u64,
}

impl ShBuffers {
    pub fn new(ctx: &Arc<Context>, env: &Image, rotation_deg: f32, intensity: f32) -> Result<Self> {
        let rows = env.desc.height;
        let storage = |name: &str, size: u64, extra: vk::BufferUsageFlags| {
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
            partials: storage(
                "sh partials",
                rows as u64 * 27 * 4,
                vk::BufferUsageFlags::empty(),
            )?,
            transform: transform(ctx, rotation_deg, intensity)?,
            coefficients: storage(
                "sh coefficients",
                9 * 16,
                vk::BufferUsageFlags::TRANSFER_SRC | vk::BufferUsageFlags::UNIFORM_BUFFER,
            )?,
            rows,
            key: super::lighting::key(&[rotation_deg, intensity]),
        })
    }
}

impl ShBuffers {
    /// The environment turned or scaled: a new transform; the coefficients
    /// are projected again by the next frame that needs them.
    pub fn set_transform(
        &mut self,
        ctx: &Arc<Context>,
        rotation_deg: f32,
        intensity: f32,
    ) -> Result<()> {
        self.transform = transform(ctx, rotation_deg, intensity)?;
        self.key = super::lighting::key(&[rotation_deg, intensity]);
        Ok(())
    }
}

/// The 9×9 rotation, then the intensity, uploaded.
fn transform(ctx: &Arc<Context>, rotation_deg: f32, intensity: f32) -> Result<Arc<Buffer>> {
    let mut transform: Vec<f32> = rotation_matrix(rotation_deg).to_vec();
    transform.push(intensity);
    upload_buffer(
        ctx,
        "sh transform",
        bytemuck::cast_slice(&transform),
        Access::ComputeBufferRead,
    )
}

impl ShPasses {
    pub fn new(pipelines: &Pipelines, sampler: Arc<Sampler>) -> Result<Self> {
        Ok(Self {
            project: pipelines.compute("sh_project.comp", &[])?,
            reduce: pipelines.compute("sh_reduce.comp", &[])?,
            sampler,
        })
    }

    /// The coefficient buffer, kept (read as a uniform buffer): `sh_project`
    /// and `sh_reduce` compute it when the transform is new.
    pub fn passes(&self, g: &mut Graph, env: &Arc<Image>, b: &ShBuffers) -> BufferHandle {
        let (mut coefficients, project) = g.import_kept_buffer(
            "sh coefficients",
            Imported::Buffer(b.coefficients.clone()),
            Access::UniformRead,
            b.key,
        );
        if !project {
            return coefficients;
        }
        let mut partials = g.import_buffer(
            "sh partials",
            Imported::Buffer(b.partials.clone()),
            Some(Access::ComputeBufferRead),
            None,
        );
        // One workgroup per row, then one workgroup sums the rows.
        g.simple_pass("sh_project", &self.project)
            .texture(env, &self.sampler)
            .write_buffer(&mut partials)
            .tag(super::TAG)
            .dispatch_groups([b.rows, 1, 1]);
        g.simple_pass("sh_reduce", &self.reduce)
            .tag(super::TAG)
            .read_buffer(&partials)
            .buffer(&b.transform)
            .write_buffer(&mut coefficients)
            .constants(&b.rows)
            .dispatch_groups([1, 1, 1]);
        coefficients
    }
}

/// Projects `env` on the GPU (rotated, scaled); returns the coefficients and the
/// frame report of the two passes (`dermis sh`, tests).
pub fn project(
    ctx: &Arc<Context>,
    env: &EnvMap,
    rotation_deg: f32,
    intensity: f32,
) -> Result<(Sh9, FrameTiming)> {
    let image = upload_env(ctx, env, 1.0)?;
    let passes = ShPasses::new(
        &Pipelines::new(ctx),
        Arc::new(Sampler::clamped(ctx, false)?),
    )?;
    let buffers = ShBuffers::new(ctx, &image, rotation_deg, intensity)?;
    let readback = Readback::new(ctx, "sh readback", 9 * 16)?;
    let mut g = Graph::new();
    let coefficients = passes.passes(&mut g, &image, &buffers);
    readback.buffer_pass(&mut g, &coefficients);
    let mut ex = Executor::new(ctx, 1)?;
    let mut reports: Vec<FrameTiming> = ex.run(g)?.into_iter().collect();
    reports.extend(ex.finish()?);
    let v: &[f32] = bytemuck::cast_slice(readback.bytes()?);
    let coeffs = std::array::from_fn(|i| Vec3::new(v[4 * i], v[4 * i + 1], v[4 * i + 2]));
    Ok((coeffs, reports.pop().unwrap_or_default()))
}
