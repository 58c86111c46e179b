//! The lighting settings of a render, resolved once from the scene: the lights
//! the frame uses (the scene's, then the environment's bright sources as
//! shadowed directional lights), each one's shadow projections (the whole mesh,
//! and the part of it the camera sees), and the environment's rotation and
//! intensity. Turning the environment makes the extracted lights and their
//! projections again; moving the camera, the focus maps.

use super::extract::ExtractedLight;
use super::shadow::{Focus, ShadowMaps, ShadowView};
use crate::frame_inputs::MAX_LIGHTS;
use crate::scene::camera::Camera;
use crate::scene::file::Occlusion;
use crate::scene::mesh::Mesh;
use crate::scene::range::PreExposure;
use crate::scene::{Light, LightSource, Scene};
use glam::Vec3;
use std::hash::{Hash, Hasher};

#[derive(Clone, Debug)]
pub struct Lighting {
    /// At most [`MAX_LIGHTS`]: the scene's, then the extracted sources.
    pub lights: Vec<Light>,
    /// Each light's shadow projections (`None`: unshadowed).
    pub maps: Vec<Option<ShadowMaps>>,
    /// Bright sources taken out of the environment (in the map's frame).
    pub extracted: Vec<ExtractedLight>,
    /// `environment.rotation_deg`, `environment.intensity`.
    pub rotation_deg: f32,
    pub intensity: f32,
    /// The scene's pre-exposure: `lights` hold it already.
    pub pre_exposure: PreExposure,
    /// `skin.occlusion` is not off.
    pub occlusion: bool,
    /// `render.shadow_resolution`.
    pub shadow_resolution: u32,
    /// The scene's own lights, and the mesh's bounding sphere (centre, radius)
    /// the shadow maps are fitted to.
    scene_lights: Vec<Light>,
    bounds: (Vec3, f32),
    /// `render.shadow_focus`: the vertices the camera sees, which the focus
    /// maps hold, and how far beyond them, mm.
    focus: bool,
    seen: Vec<Vec3>,
    margin_mm: f32,
    /// The mesh's vertices, mm (the focus maps' nearest surfaces).
    vertices: Vec<Vec3>,
}

impl Lighting {
    /// The scene's lighting; the focus maps hold what its camera sees, grown by
    /// `margin_mm`.
    pub fn resolve(scene: &Scene, extracted: Vec<ExtractedLight>, margin_mm: f32) -> Self {
        let (lo, hi) = scene.mesh.bounds().unwrap_or_default();
        let env = &scene.file.environment;
        let mut lighting = Self {
            lights: Vec::new(),
            maps: Vec::new(),
            extracted,
            rotation_deg: env.rotation_deg,
            intensity: env.intensity,
            pre_exposure: scene.pre_exposure,
            occlusion: scene.file.skin.occlusion != Occlusion::Off,
            shadow_resolution: scene.file.render.shadow_resolution,
            scene_lights: scene.lights.clone(),
            bounds: (0.5 * (lo + hi), 0.5 * lo.distance(hi)),
            focus: scene.file.render.shadow_focus,
            seen: seen_vertices(scene),
            margin_mm,
            vertices: scene.mesh.positions.clone(),
        };
        lighting.turn(env.rotation_deg);
        lighting
    }

    /// The environment turned to `rotation_deg`: the extracted lights and the
    /// shadow projections made again.
    pub fn turn(&mut self, rotation_deg: f32) {
        self.rotation_deg = rotation_deg;
        self.lights = self.frame_lights();
        self.maps = self.shadow_maps();
    }

    /// The camera moved: the vertices it sees again, and the focus maps that
    /// changed with them (Focus::fit snaps windows, so a small move changes
    /// none). True when a projection changed.
    pub fn set_camera(&mut self, scene: &Scene) -> bool {
        if !self.focus {
            return false;
        }
        self.seen = seen_vertices(scene);
        let maps = self.shadow_maps();
        let changed = maps != self.maps;
        self.maps = maps;
        changed
    }

    /// The factor the GPU scales the uploaded map by: intensity · P / M.
    pub fn env_factor(&self) -> f32 {
        let p = self.pre_exposure;
        (f64::from(self.intensity) * f64::from(p.lighting) / f64::from(p.map)) as f32
    }

    /// What the SH projection is computed from (rotation, the map's factor).
    pub fn sh_key(&self) -> u64 {
        key(&[self.rotation_deg, self.env_factor()])
    }

    /// Atlas tiles a shadowed light takes: its whole map, and its focus map
    /// when `render.shadow_focus` is on.
    pub fn tiles_per_light(&self) -> usize {
        1 + usize::from(self.focus)
    }

    /// The atlas's tiles in order: each shadowed light's whole map, then its
    /// focus map (`None`: left empty).
    pub fn tiles(&self) -> Vec<Option<ShadowView>> {
        let mut tiles = Vec::new();
        for m in self.maps.iter().flatten() {
            tiles.push(Some(m.whole));
            if self.focus {
                tiles.push(m.focus.map(|f| f.view));
            }
        }
        tiles
    }

    /// What the shadow maps and the soft lights' visibility are computed from:
    /// the lights and their projections.
    pub fn shadow_key(&self) -> u64 {
        let mut values = Vec::new();
        for l in &self.lights {
            let (LightSource::Directional(p) | LightSource::Point(p)) = l.source;
            values.extend(p.to_array());
            values.push(l.angular_radius);
        }
        for v in self.tiles() {
            values.extend(v.map_or([0.0; 16], |v| v.view_proj.to_cols_array()));
        }
        key(&values)
    }

    /// The scene's lights, then the extracted sources as shadowed directional
    /// lights of their power, turned and scaled like the environment; all
    /// pre-exposed.
    fn frame_lights(&self) -> Vec<Light> {
        let p = self.pre_exposure.lighting;
        let all: Vec<Light> = self
            .scene_lights
            .iter()
            .map(|l| Light {
                irradiance: l.irradiance * p,
                ..*l
            })
            .chain(self.extracted.iter().map(|x| Light {
                source: LightSource::Directional(x.world_direction(self.rotation_deg)),
                // A uniform cap of radius α delivers (1 + cos α)/2 of its ∫L dω to a
                // surface facing it.
                irradiance: x.power
                    * (f64::from(self.intensity) * f64::from(p)) as f32
                    * 0.5
                    * (1.0 + x.angular_radius_rad.cos()),
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

    /// The focus window of a light's `whole` map: where the camera looks.
    fn focus_of(&self, whole: &ShadowView) -> Option<Focus> {
        let (seen, vertices) = (&self.seen, &self.vertices);
        Focus::fit(
            whole,
            seen,
            vertices,
            self.margin_mm,
            self.shadow_resolution,
        )
    }

    /// The shadow projections of each light (`None`: unshadowed).
    fn shadow_maps(&self) -> Vec<Option<ShadowMaps>> {
        let (centre, radius) = self.bounds;
        let res = self.shadow_resolution;
        self.lights
            .iter()
            .map(|l| {
                let view = l
                    .shadow
                    .then(|| ShadowView::fit(l.source, centre, radius, res))
                    .flatten()
                    .map(|whole| ShadowMaps {
                        whole,
                        focus: self.focus_of(&whole),
                    });
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

/// The vertices of `scene`'s mesh its camera sees, at the aspect of the
/// render's size: inside the view frustum and facing the camera (occlusion
/// aside); none when `render.shadow_focus` is off.
fn seen_vertices(scene: &Scene) -> Vec<Vec3> {
    let r = &scene.file.render;
    if !r.shadow_focus {
        return Vec::new();
    }
    seen_by(&scene.camera, r.width as f32 / r.height as f32, &scene.mesh)
}

/// The vertices of `mesh` that `camera` sees at `aspect`.
fn seen_by(camera: &Camera, aspect: f32, mesh: &Mesh) -> Vec<Vec3> {
    let vp = camera.view_projection(aspect);
    mesh.positions
        .iter()
        .zip(&mesh.normals)
        .filter(|(p, n)| {
            let c = vp * p.extend(1.0);
            let inside = c.x.abs() <= c.w && c.y.abs() <= c.w && c.z >= 0.0 && c.z <= c.w;
            inside && n.dot(camera.position - **p) > 0.0
        })
        .map(|(p, _)| *p)
        .collect()
}

/// A key of `values` (their bits) for kept resources (graph::Kept).
pub fn key(values: &[f32]) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for v in values {
        v.to_bits().hash(&mut h);
    }
    h.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_camera_sees_what_is_in_view_and_faces_it() {
        let camera = Camera::orbit_at(Vec3::ZERO, 0.0, 0.0, 500.0, 30.0);
        let mesh = Mesh {
            positions: vec![
                Vec3::ZERO,                 // in view, facing the camera
                Vec3::new(0.0, 0.0, -10.0), // in view, facing away
                Vec3::new(400.0, 0.0, 0.0), // outside the field of view
                Vec3::new(0.0, 0.0, 600.0), // behind the camera
            ],
            normals: vec![Vec3::Z, -Vec3::Z, Vec3::Z, Vec3::Z],
            ..Mesh::default()
        };
        assert_eq!(seen_by(&camera, 1.0, &mesh), [Vec3::ZERO]);
    }
}
