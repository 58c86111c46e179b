//! The frame's inputs on the GPU: the vocabulary every pass shares. Vertex layout,
//! mesh buffers, uploaded textures and environment, target formats, per-frame
//! uniforms and samplers. Below the passes (`skin/`, `light/`, `post/`), above
//! `scene/` (what it uploads) and `graph/`.

mod formats;
mod mesh;
mod samplers;
mod textures;
mod uniforms;

pub use formats::{DEPTH_FORMAT, HDR_FORMAT, SHADOW_FORMAT};
pub use mesh::{MeshBuffers, Vertex, VERTEX_ATTRIBUTES};
pub use samplers::Samplers;
pub use textures::{upload_env, upload_rgba8};
pub use uniforms::{FrameUniforms, ShaderVariant, MAX_LIGHTS};

use crate::gpu::{Buffer, Image, Sampler};
use std::sync::Arc;

/// What every frame reads that does not change during a render.
pub struct FrameInputs {
    /// [`FrameUniforms`]: camera, lights, environment rotation.
    pub uniforms: Arc<Buffer>,
    pub mesh: Arc<MeshBuffers>,
    pub albedo: Arc<Image>,
    pub normal: Arc<Image>,
    /// Per vertex the SH transfer (light::occlusion), then the SH of the
    /// visibility the environment's specular reads through its lobe
    /// (light::occlusion::lobe_visibility_for): 18 floats.
    pub transfer: Arc<Buffer>,
    /// Per vertex the interreflected transfer (light::interreflection) and the
    /// environment's transmitted one (light::transmission), each 9 floats per
    /// channel (R, G, B): 54 floats, zeros where a term is off.
    pub rgb_transfer: Arc<Buffer>,
    /// Specular intensity and roughness maps (read by the specular term; the face
    /// regions reach it blended, skin::tables).
    pub specular: Arc<Image>,
    pub roughness: Arc<Image>,
    /// Lights, shadows, occlusion and maps the shading passes specialise on.
    pub variant: ShaderVariant,
    /// The environment as given: what the skybox shows.
    pub env: Arc<Image>,
    /// What lights the skin through SH9 and the specular prefilter: the
    /// environment less the bright sources taken out as lights (light::extract);
    /// the same image when none were.
    pub lighting_env: Arc<Image>,
    /// Linear where the device filters RGBA32F, else nearest.
    pub env_sampler: Arc<Sampler>,
    pub samplers: Arc<Samplers>,
}
