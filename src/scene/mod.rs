//! Everything the renderer reads: meshes (glTF or the built-in head), textures,
//! the environment, camera and lights, from a TOML scene file plus CLI overrides.

pub mod camera;
pub mod checker;
pub mod env;
pub mod file;
pub mod gltf;
pub mod head;
pub mod jpeg_scan;
pub mod mesh;
pub mod overrides;
pub mod range;
pub mod texture;

#[cfg(test)]
mod uv_origin_tests;

use crate::error::Result;
use camera::Camera;
use env::EnvMap;
use file::{LightKind, SceneFile, UvOrigin};
use glam::Vec3;
use mesh::Mesh;
pub use overrides::{Overrides, SceneArg};
use std::path::PathBuf;
use texture::{Encoding, Texture};

/// Size of procedural environments (`uniform:`, `sky`): 1024×512, the size of the
/// CC0 maps in assets/env.
pub const PROCEDURAL_ENV_SIZE: (u32, u32) = (1024, 512);

/// Where a light is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightSource {
    /// Infinitely far away: the unit direction towards the light.
    Directional(Vec3),
    /// A position in the scene, mm.
    Point(Vec3),
}

/// An explicit light as the shaders use it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    pub source: LightSource,
    /// Irradiance on a surface facing the light; for a point light at
    /// [`POINT_LIGHT_REFERENCE_MM`], falling off as 1/d².
    pub irradiance: Vec3,
    /// Whether it casts shadows (a shadow map, light::shadow).
    pub shadow: bool,
    /// Angular radius of the source seen from the scene, radians (0: a point or
    /// a perfectly parallel beam). Directional lights only: it sets the penumbra
    /// and widens the specular lobe.
    pub angular_radius: f32,
}

/// The distance at which a point light's `intensity` is its irradiance (scene-format.md).
pub const POINT_LIGHT_REFERENCE_MM: f32 = 1000.0;

impl Light {
    /// Unit direction towards the light from `x` and the irradiance it delivers
    /// there to a surface facing it (unshadowed).
    pub fn at(&self, x: Vec3) -> (Vec3, Vec3) {
        match self.source {
            LightSource::Directional(d) => (d, self.irradiance),
            LightSource::Point(p) => {
                let d = p - x;
                let falloff = POINT_LIGHT_REFERENCE_MM * POINT_LIGHT_REFERENCE_MM
                    / d.length_squared().max(1e-6);
                (d.normalize_or_zero(), self.irradiance * falloff)
            }
        }
    }
}

/// A scene loaded into memory, in millimetres.
#[derive(Clone)]
pub struct Scene {
    pub mesh: Mesh,
    pub albedo: Texture,
    pub normal: Texture,
    pub specular: Texture,
    /// Beckmann roughness m as grey/255; the default is d'Eon's m = 0.3 (77/255).
    pub roughness: Texture,
    pub regions: Texture,
    pub env: EnvMap,
    pub camera: Camera,
    pub lights: Vec<Light>,
    /// The powers of two its light is rendered at (range::PreExposure).
    pub pre_exposure: range::PreExposure,
    /// The settings it was loaded from (skin, render, environment rotation and intensity).
    pub file: SceneFile,
}

impl Scene {
    pub fn load(file: SceneFile) -> Result<Scene> {
        let t = &file.textures;
        let bottom_left = t.uv_origin == UvOrigin::BottomLeft;
        // Maps from the file, turned to glTF's top-left origin; stand-ins are uniform.
        let load = |path: &Option<PathBuf>, encoding, default: [u8; 4]| -> Result<Texture> {
            Ok(match path {
                Some(p) => {
                    let mut texture = texture::load_texture(p, encoding)?;
                    if bottom_left {
                        texture.flip_vertical();
                    }
                    texture
                }
                None => Texture::solid(default, encoding),
            })
        };
        let (mut mesh, albedo, normal, regions) = match &file.mesh {
            Some(path) => (
                gltf::load_mesh(path, file.mm_per_unit)?,
                load(&t.albedo, Encoding::Srgb, texture::DEFAULT_ALBEDO_SRGB)?,
                load(&t.normal, Encoding::Linear, texture::FLAT_NORMAL)?,
                load(&t.regions, Encoding::Linear, texture::DEFAULT_REGION)?,
            ),
            None => {
                let head = head::default_head().clone();
                let size = head.texture_size;
                let tex = |rgba8, encoding| Texture {
                    width: size,
                    height: size,
                    encoding,
                    rgba8,
                };
                // A scene file may still replace the built-in head's maps.
                let albedo = match &t.albedo {
                    Some(_) => load(&t.albedo, Encoding::Srgb, texture::DEFAULT_ALBEDO_SRGB)?,
                    None => tex(head.albedo_srgb, Encoding::Srgb),
                };
                let normal = match &t.normal {
                    Some(_) => load(&t.normal, Encoding::Linear, texture::FLAT_NORMAL)?,
                    None => tex(head.normal_detail, Encoding::Linear),
                };
                let regions = match &t.regions {
                    Some(_) => load(&t.regions, Encoding::Linear, texture::DEFAULT_REGION)?,
                    None => tex(head.regions, Encoding::Linear),
                };
                (head.mesh, albedo, normal, regions)
            }
        };
        let albedo = if t.test_texture {
            checker::albedo(t.uv_origin)
        } else {
            albedo
        };
        // A flipped normal map's +Y points toward increasing v (Mesh::negate_bitangent_sign).
        if bottom_left && t.normal.is_some() {
            mesh.negate_bitangent_sign();
        }
        let specular = load(&t.specular, Encoding::Linear, texture::DEFAULT_SPECULAR)?;
        // m = 0.3 (GPU Gems 3 §14.3) encoded as grey/255.
        let roughness = load(&t.roughness, Encoding::Linear, [77, 77, 77, 255])?;
        let (w, h) = PROCEDURAL_ENV_SIZE;
        let (env, report) = env::resolve(&file.environment.source, w, h)?;
        if report.total() > 0 {
            log::warn!(
                "{}: replaced {} NaN, {} infinite and {} negative texel values",
                file.environment.source,
                report.nan,
                report.inf,
                report.negative
            );
        }
        let bounds = mesh
            .bounds()
            .ok_or_else(|| crate::Error::Input("the mesh is empty".into()))?;
        let camera = camera_for(&file, bounds);
        let lights = file
            .lights
            .iter()
            .map(|l| Light {
                source: match l.kind {
                    LightKind::Directional => LightSource::Directional(
                        -Vec3::from(l.direction.unwrap_or([0.0, -1.0, 0.0])).normalize_or_zero(),
                    ),
                    LightKind::Point => {
                        LightSource::Point(Vec3::from(l.position.unwrap_or([0.0, 0.0, 1000.0])))
                    }
                },
                irradiance: Vec3::from(l.color) * l.intensity,
                shadow: l.shadow,
                angular_radius: 0.5 * l.angular_diameter_deg.to_radians(),
            })
            .collect::<Vec<_>>();
        let pre_exposure =
            range::pre_exposure(&file, &env, &lights, &mesh).map_err(crate::Error::Input)?;
        Ok(Scene {
            mesh,
            albedo,
            normal,
            specular,
            roughness,
            regions,
            env,
            camera,
            lights,
            pre_exposure,
            file,
        })
    }
}

/// The scene's mesh alone: its glTF file, or the built-in head.
pub fn load_mesh(file: &SceneFile) -> Result<Mesh> {
    Ok(match &file.mesh {
        Some(path) => gltf::load_mesh(path, file.mm_per_unit)?,
        None => head::default_head().mesh.clone(),
    })
}

/// The scene's camera; with neither a position nor an orbit given, it frames the
/// mesh from the front (yaw 0, pitch 0).
pub fn camera_for(file: &SceneFile, bounds: (Vec3, Vec3)) -> Camera {
    let c = &file.camera;
    let centre = 0.5 * (bounds.0 + bounds.1);
    let mut camera = if c.position.is_none() && c.orbit.is_none() {
        Camera::orbit(bounds, 0.0, 0.0, c.fov_deg, 0.9)
    } else {
        let (position, target, up) = c.eye_target_up(centre);
        Camera {
            position,
            target,
            up,
            fov_y_deg: c.fov_deg,
            near_mm: c.near_mm,
            far_mm: c.far_mm,
        }
    };
    camera.fov_y_deg = c.fov_deg;
    camera
}
