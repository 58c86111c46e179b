//! The shadowed lights' light through thin skin (translucent shadow maps,
//! d'Eon & Luebke §14.5.3; Jimenez et al. 2010; docs/records/2026-11-26-transmission.md, "Transmission"),
//! in texture space, once per lighting: it depends on the lights, their shadow
//! atlas, the mesh and its maps, not on the camera, so it is drawn by the
//! render's first frame that needs it and kept by the atlas's key, as the soft
//! lights' visibility is (light::visibility). Both sides of the surface
//! (translucent.frag); the final pass reads the side it shades with one
//! bilinear lookup instead of a shadow-map thickness and six exponentials per
//! light and pixel (docs/records/2026-11-26-per-render-terms.md).

use super::medium_tables::MediumTables;
use super::tables::SpecularTables;
use super::{uv_pipeline, UV_FORMAT};
use crate::error::Result;
use crate::frame_inputs::{FrameInputs, ShaderVariant};
use crate::gpu::{Image, ImageDesc, Pipeline, Pipelines};
use crate::graph::upload::upload_texture;
use crate::graph::{Access, Graph, ImageHandle, LoadOp};
use ash::vk;
use std::sync::Arc;

/// Largest side of the textures: the transmittance changes over millimetres
/// and 1024² is ~0.6 mm per texel on the scan (as the stretch maps,
/// skin::stretch::MAX_RESOLUTION).
pub const MAX_RESOLUTION: u32 = 1024;
/// The textures: the front side's (the mesh's normal) and the back's.
const NAMES: [&str; 2] = ["translucent_front", "translucent_back"];

pub struct TranslucentPass {
    pipeline: Arc<Pipeline>,
    /// The term is on (`skin.transmission` > 0) and some light has a shadow
    /// map; else the textures are 1×1 and cleared, so the final pass always has
    /// them to bind.
    on: bool,
    textures: [Arc<Image>; 2],
    /// A medium's T(d)/albedo by thickness (1×1 and unread without one).
    table: Arc<Image>,
    /// The thickness of the table's last sample, mm; 0 without a medium.
    table_max_mm: f32,
}

/// translucent.frag's push constants.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Constants {
    /// Per Gaussian its RGB weight and its variance (mm²).
    profile: [[f32; 4]; 6],
    table_max_mm: f32,
}

impl TranslucentPass {
    /// The pass and its textures at min(`resolution`, [`MAX_RESOLUTION`])² for
    /// an irradiance texture of `resolution`²; `on`: the scene transmits;
    /// `medium`: T(d) from its table instead of the profile's Gaussians.
    pub fn new(
        pipelines: &Pipelines,
        variant: &ShaderVariant,
        resolution: u32,
        on: bool,
        medium: Option<&MediumTables>,
    ) -> Result<Self> {
        let ctx = pipelines.ctx();
        let on = on && variant.shadowed != 0;
        let side = if on {
            resolution.min(MAX_RESOLUTION)
        } else {
            1
        };
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT
            | vk::ImageUsageFlags::SAMPLED
            | vk::ImageUsageFlags::TRANSFER_SRC;
        let desc = ImageDesc::new(side, side, UV_FORMAT);
        let image = |name| Image::new(ctx, name, desc, usage).map(Arc::new);
        let texels: Vec<[f32; 4]> = match medium {
            Some(t) => t
                .transmittance_over_albedo()
                .iter()
                .map(|v| v.extend(1.0).to_array())
                .collect(),
            None => vec![[0.0; 4]],
        };
        let halves: Vec<u8> = texels
            .iter()
            .flatten()
            .flat_map(|&v| half::f16::from_f32(v).to_le_bytes())
            .collect();
        let table = upload_texture(
            ctx,
            "transmittance table",
            ImageDesc::new(texels.len() as u32, 1, UV_FORMAT),
            &halves,
        )?;
        let mut specialization = variant.specialization().to_vec();
        specialization.push(u32::from(medium.is_some()));
        Ok(Self {
            pipeline: uv_pipeline(
                pipelines,
                ("uv.vert", "translucent.frag"),
                &[UV_FORMAT; 2],
                &specialization,
            )?,
            on,
            textures: [image(NAMES[0])?, image(NAMES[1])?],
            table,
            table_max_mm: medium.map_or(0.0, |t| t.max_thickness_mm),
        })
    }

    /// The front and back textures, from the lights' shadow `atlas`
    /// (light::shadow), kept for `key` (the atlas's); `profile`: per Gaussian
    /// its RGB weight and its variance (mm²).
    pub fn pass(
        &self,
        g: &mut Graph,
        inputs: &FrameInputs,
        tables: &SpecularTables,
        (atlas, key): (&ImageHandle, u64),
        profile: &[[f32; 4]; 6],
    ) -> [ImageHandle; 2] {
        let [front, back] = &self.textures;
        let images = [(NAMES[0], front), (NAMES[1], back)];
        let (mut out, draw) = g.import_kept_images(images, Access::ShaderSampled, key);
        if !draw {
            return out;
        }
        let s = &inputs.samplers;
        let pass = g
            .simple_pass("translucent", &self.pipeline)
            .uniform(&inputs.uniforms)
            .sample(atlas, &s.shadow)
            .sample(atlas, &s.nearest)
            .texture(&inputs.normal, &s.linear);
        let [front, back] = &mut out;
        let pass = tables
            .bind(pass, inputs)
            .texture(&self.table, &s.linear)
            .color(front, LoadOp::Clear([0.0; 4]))
            .color(back, LoadOp::Clear([0.0; 4]))
            .constants(&Constants {
                profile: *profile,
                table_max_mm: self.table_max_mm,
            });
        if self.on {
            inputs.mesh.draw(pass);
        } else {
            pass.record(|_| {});
        }
        out
    }
}
