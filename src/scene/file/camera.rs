//! `[camera]` and `[[lights]]`.

use glam::Vec3;
use serde::Deserialize;

use super::{finite, finite3, in_range, non_negative, nonzero3, positive};

/// Camera: `position`/`target`/`up` (world mm) or an `orbit` around the mesh centre.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Camera {
    pub position: Option<[f32; 3]>,
    /// Point looked at; `None` = the mesh's bounding-box centre.
    pub target: Option<[f32; 3]>,
    /// `None` = +Y.
    pub up: Option<[f32; 3]>,
    pub orbit: Option<Orbit>,
    /// Vertical field of view, degrees.
    pub fov_deg: f32,
    pub near_mm: f32,
    pub far_mm: f32,
}

impl Default for Camera {
    fn default() -> Camera {
        Camera {
            position: None,
            target: None,
            up: None,
            orbit: None,
            fov_deg: 30.0,
            near_mm: 10.0,
            far_mm: 10_000.0,
        }
    }
}

/// A camera on a sphere around the mesh's bounding-box centre, looking at it.
/// yaw 0, pitch 0 puts the camera on +Z (the glTF front), +Y up.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Orbit {
    /// Rotation about +Y, degrees, counter-clockwise seen from above (+X side at 90).
    pub yaw_deg: f32,
    /// Elevation above the horizontal plane, degrees, in (-90, 90).
    pub pitch_deg: f32,
    /// Distance from the centre, mm.
    pub distance_mm: f32,
}

impl Default for Orbit {
    fn default() -> Orbit {
        Orbit {
            yaw_deg: 0.0,
            pitch_deg: 0.0,
            distance_mm: 700.0,
        }
    }
}

impl Camera {
    /// Eye, target and up vector (world mm) given the mesh's bounding-box centre.
    pub fn eye_target_up(&self, mesh_centre: Vec3) -> (Vec3, Vec3, Vec3) {
        let up = self.up.map(Vec3::from).unwrap_or(Vec3::Y);
        match self.position {
            Some(p) => (
                Vec3::from(p),
                self.target.map(Vec3::from).unwrap_or(mesh_centre),
                up,
            ),
            None => {
                let o = self.orbit.unwrap_or_default();
                let (yaw, pitch) = (o.yaw_deg.to_radians(), o.pitch_deg.to_radians());
                let dir = Vec3::new(
                    pitch.cos() * yaw.sin(),
                    pitch.sin(),
                    pitch.cos() * yaw.cos(),
                );
                (mesh_centre + o.distance_mm * dir, mesh_centre, up)
            }
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LightKind {
    Directional,
    Point,
}

/// An analytic light added to the environment.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Light {
    pub kind: LightKind,
    /// Directional: the direction light travels (from the light into the scene).
    pub direction: Option<[f32; 3]>,
    /// Point: world position, mm.
    pub position: Option<[f32; 3]>,
    /// Linear RGB.
    #[serde(default = "white")]
    pub color: [f32; 3],
    /// Directional: irradiance on a surface facing the light, in environment
    /// radiance units × sr. Point: the same at 1000 mm; falls off as 1/d².
    #[serde(default = "one")]
    pub intensity: f32,
    /// Casts shadows through the shadow/depth pass.
    #[serde(default = "yes")]
    pub shadow: bool,
    /// Directional: the source's angular diameter, degrees (the sun: 0.53);
    /// 0 is a parallel beam. It softens the shadow and widens the highlight.
    #[serde(default)]
    pub angular_diameter_deg: f32,
}

fn white() -> [f32; 3] {
    [1.0, 1.0, 1.0]
}
fn one() -> f32 {
    1.0
}
fn yes() -> bool {
    true
}

impl Camera {
    pub(super) fn validate(&self) -> Result<(), String> {
        let fov = self.fov_deg;
        finite("camera.fov_deg", fov)?;
        if !(fov > 1.0 && fov < 179.0) {
            return Err(format!(
                "camera.fov_deg = {fov}: must be in (1, 179) degrees"
            ));
        }
        positive("camera.near_mm", self.near_mm)?;
        positive("camera.far_mm", self.far_mm)?;
        if self.far_mm <= self.near_mm {
            return Err(format!(
                "camera.far_mm = {} must be greater than camera.near_mm = {}",
                self.far_mm, self.near_mm
            ));
        }
        match (self.position, &self.orbit) {
            (Some(_), Some(_)) => {
                return Err(
                    "camera: give either position (with target, up) or orbit, not both".into(),
                )
            }
            (None, _) if self.target.is_some() || self.up.is_some() => {
                return Err("camera.target and camera.up need camera.position".into())
            }
            _ => {}
        }
        if let Some(p) = self.position {
            let p = finite3("camera.position", p)?;
            let up = match self.up {
                Some(u) => nonzero3("camera.up", u)?,
                None => Vec3::Y,
            };
            if let Some(t) = self.target {
                let view = finite3("camera.target", t)? - p;
                if view.length_squared() == 0.0 {
                    return Err("camera.target equals camera.position".into());
                }
                if view.normalize().cross(up.normalize()).length() < 1e-3 {
                    return Err("camera.up is parallel to the viewing direction".into());
                }
            }
        }
        if let Some(o) = &self.orbit {
            finite("camera.orbit.yaw_deg", o.yaw_deg)?;
            finite("camera.orbit.pitch_deg", o.pitch_deg)?;
            if !(o.pitch_deg > -90.0 && o.pitch_deg < 90.0) {
                return Err(format!(
                    "camera.orbit.pitch_deg = {}: must be in (-90, 90) degrees",
                    o.pitch_deg
                ));
            }
            positive("camera.orbit.distance_mm", o.distance_mm)?;
        }
        Ok(())
    }
}

impl Light {
    pub(super) fn validate(&self, key: &str) -> Result<(), String> {
        match self.kind {
            LightKind::Directional => {
                if self.position.is_some() {
                    return Err(format!(
                        "{key}.position: a directional light has a direction, not a position"
                    ));
                }
                let d = self.direction.ok_or_else(|| {
                    format!("{key}.direction is required for a directional light")
                })?;
                nonzero3(&format!("{key}.direction"), d)?;
                // A cap wider than 40° is no longer one direction (its cosine
                // lobe and shadow would be far off).
                in_range(
                    &format!("{key}.angular_diameter_deg"),
                    self.angular_diameter_deg,
                    0.0,
                    40.0,
                )?;
            }
            LightKind::Point => {
                if self.angular_diameter_deg != 0.0 {
                    return Err(format!(
                        "{key}.angular_diameter_deg: only directional lights have an angular size"
                    ));
                }
                if self.direction.is_some() {
                    return Err(format!(
                        "{key}.direction: a point light has a position, not a direction"
                    ));
                }
                let p = self
                    .position
                    .ok_or_else(|| format!("{key}.position is required for a point light"))?;
                finite3(&format!("{key}.position"), p)?;
            }
        }
        for (c, v) in ["r", "g", "b"].iter().zip(self.color) {
            non_negative(&format!("{key}.color.{c}"), v)?;
        }
        non_negative(&format!("{key}.intensity"), self.intensity)
    }
}
