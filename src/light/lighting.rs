//! The lighting settings of a render, resolved once from the scene: the lights
//! the frame uses (the scene's, then the environment's bright sources as
//! shadowed directional lights), each one's shadow projection, and the
//! environment's rotation and intensity. Turning the environment makes the
//! extracted lights and their projections again.

use super::extract::ExtractedLight;
use super::shadow::ShadowView;
use crate::frame::MAX_LIGHTS;
use crate::scene::file::Occlusion;
use crate::scene::{Light, LightSource, Scene};
use glam::Vec3;
use std::hash::{Hash, Hasher};

#[derive(Clone, Debug)]
pub struct Lighting {
    /// At most [`MAX_LIGHTS`]: the scene's, then the extracted sources.
    pub lights: Vec<Light>,
    /// Each light's shadow projection (`None`: unshadowed).
    pub views: Vec<Option<ShadowView>>,
    /// Bright sources taken out of the environment (in the map's frame).
    pub extracted: Vec<ExtractedLight>,
    /// `environment.rotation_deg`, `environment.intensity`.
    pub rotation_deg: f32,
    pub intensity: f32,
    /// `skin.occlusion` is not off.
    pub occlusion: bool,
    /// `render.shadow_resolution`.
    pub shadow_resolution: u32,
    /// The scene's own lights, and the mesh's bounding sphere (centre, radius)
    /// the shadow maps are fitted to.
    scene_lights: Vec<Light>,
    bounds: (Vec3, f32),
}

impl Lighting {
    pub fn resolve(scene: &Scene, extracted: Vec<ExtractedLight>) -> Self {
        let (lo, hi) = scene.mesh.bounds().unwrap_or_default();
        let env = &scene.file.environment;
        let mut lighting = Self {
            lights: Vec::new(),
            views: Vec::new(),
            extracted,
            rotation_deg: env.rotation_deg,
            intensity: env.intensity,
            occlusion: scene.file.skin.occlusion != Occlusion::Off,
            shadow_resolution: scene.file.render.shadow_resolution,
            scene_lights: scene.lights.clone(),
            bounds: (0.5 * (lo + hi), 0.5 * lo.distance(hi)),
        };
        lighting.turn(env.rotation_deg);
        lighting
    }

    /// The environment turned to `rotation_deg`: the extracted lights and the
    /// shadow projections made again.
    pub fn turn(&mut self, rotation_deg: f32) {
        self.rotation_deg = rotation_deg;
        self.lights = self.frame_lights();
        self.views = self.shadow_views();
    }

    /// What the SH projection is computed from (rotation, intensity).
    pub fn sh_key(&self) -> u64 {
        key(&[self.rotation_deg, self.intensity])
    }

    /// What the shadow maps and the soft lights' visibility are computed from:
    /// the lights and their projections.
    pub fn shadow_key(&self) -> u64 {
        let mut values = Vec::new();
        for (l, v) in self.lights.iter().zip(&self.views) {
            let (LightSource::Directional(p) | LightSource::Point(p)) = l.source;
            values.extend(p.to_array());
            values.push(l.angular_radius);
            if let Some(v) = v {
                values.extend(v.view_proj.to_cols_array());
            }
        }
        key(&values)
    }

    /// The scene's lights, then the extracted sources as shadowed directional
    /// lights of their power, turned and scaled like the environment.
    fn frame_lights(&self) -> Vec<Light> {
        let all: Vec<Light> = self
            .scene_lights
            .iter()
            .copied()
            .chain(self.extracted.iter().map(|x| Light {
                source: LightSource::Directional(x.world_direction(self.rotation_deg)),
                // A uniform cap of radius α delivers (1 + cos α)/2 of its ∫L dω to a
                // surface facing it.
                irradiance: x.power * self.intensity * 0.5 * (1.0 + x.angular_radius_rad.cos()),
                shadow: true,
                angular_radius: x.angular_radius_rad,
            }))
            .collect();
        if all.len() > MAX_LIGHTS {
            log::warn!(
                "only the first {MAX_LIGHTS} of {} lights ({} from the environment) are used",
                all.len(),
                self.extracted.len()
            );
        }
        all.into_iter().take(MAX_LIGHTS).collect()
    }

    /// The shadow projection of each light (`None`: unshadowed).
    fn shadow_views(&self) -> Vec<Option<ShadowView>> {
        let (centre, radius) = self.bounds;
        self.lights
            .iter()
            .map(|l| {
                let view = l
                    .shadow
                    .then(|| ShadowView::fit(l.source, centre, radius, self.shadow_resolution))
                    .flatten();
                if l.shadow && view.is_none() {
                    log::warn!(
                        "{:?} is inside the mesh's bounding sphere (radius {radius:.0} mm): \
                         one shadow map cannot hold every direction; it casts no shadow",
                        l.source
                    );
                }
                view
            })
            .collect()
    }
}

/// A key of `values` (their bits) for kept resources (graph::Kept).
pub fn key(values: &[f32]) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for v in values {
        v.to_bits().hash(&mut h);
    }
    h.finish()
}
