//! The viewer's camera: an orbit around a target (yaw, pitch, distance), moved
//! by the mouse: left drag orbits, right or middle drag pans the target in the
//! view plane, the wheel zooms (a factor per notch); with Shift, a left drag
//! turns the environment instead (its SH rotation, `environment.rotation_deg`).

use crate::scene::camera::Camera;
use glam::Vec3;

/// Degrees of orbit per pixel dragged.
const DEGREES_PER_PIXEL: f32 = 0.3;
/// Distance factor per wheel notch (10 %).
const ZOOM_PER_NOTCH: f32 = 1.1;
/// Pitch stays short of the poles, where yaw loses its meaning.
const MAX_PITCH_DEG: f32 = 85.0;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    pub target: Vec3,
    pub yaw_deg: f32,
    pub pitch_deg: f32,
    pub distance_mm: f32,
    pub fov_y_deg: f32,
}

impl Orbit {
    /// The orbit that puts a camera where `camera` is, looking at its target.
    pub fn of(camera: &Camera) -> Orbit {
        let d = camera.position - camera.target;
        let distance = d.length().max(1e-3);
        let dir = d / distance;
        Orbit {
            target: camera.target,
            yaw_deg: dir.x.atan2(dir.z).to_degrees(),
            pitch_deg: dir.y.clamp(-1.0, 1.0).asin().to_degrees(),
            distance_mm: distance,
            fov_y_deg: camera.fov_y_deg,
        }
    }

    pub fn camera(&self) -> Camera {
        Camera::orbit_at(
            self.target,
            self.yaw_deg,
            self.pitch_deg,
            self.distance_mm,
            self.fov_y_deg,
        )
    }

    /// A left drag of (dx, dy) pixels: right turns the camera left around the
    /// target (the head turns right), down raises it.
    pub fn rotate(&mut self, dx: f32, dy: f32) {
        self.yaw_deg -= dx * DEGREES_PER_PIXEL;
        self.pitch_deg =
            (self.pitch_deg + dy * DEGREES_PER_PIXEL).clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG);
    }

    /// A pan of (dx, dy) pixels in a window `height` pixels tall: the target
    /// follows the cursor in the view plane, at the target's depth.
    pub fn pan(&mut self, dx: f32, dy: f32, height: f32) {
        let camera = self.camera();
        let forward = (camera.target - camera.position).normalize();
        let right = forward.cross(camera.up).normalize();
        let up = right.cross(forward);
        // Millimetres per pixel at the target's depth.
        let scale =
            2.0 * self.distance_mm * (0.5 * self.fov_y_deg.to_radians()).tan() / height.max(1.0);
        self.target += (-dx * right + dy * up) * scale;
    }

    /// `notches` of the wheel: positive zooms in.
    pub fn zoom(&mut self, notches: f32) {
        self.distance_mm = (self.distance_mm / ZOOM_PER_NOTCH.powf(notches)).clamp(10.0, 1e5);
    }
}

/// The environment's rotation after a Shift-drag of `dx` pixels, in [0, 360).
pub fn turn_environment(rotation_deg: f32, dx: f32) -> f32 {
    (rotation_deg + dx * DEGREES_PER_PIXEL).rem_euclid(360.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_orbit_reproduces_the_camera_it_was_made_from() {
        let camera = Camera::orbit_at(Vec3::new(0.0, 60.0, 0.0), 20.0, 5.0, 672.0, 30.0);
        let orbit = Orbit::of(&camera);
        assert!((orbit.yaw_deg - 20.0).abs() < 1e-3 && (orbit.pitch_deg - 5.0).abs() < 1e-3);
        assert!(orbit.camera().position.distance(camera.position) < 1e-2);
    }

    #[test]
    fn dragging_orbits_pans_and_zooms() {
        let mut o = Orbit::of(&Camera::orbit_at(Vec3::ZERO, 0.0, 0.0, 500.0, 30.0));
        o.rotate(100.0, 0.0);
        assert!((o.yaw_deg + 30.0).abs() < 1e-4);
        o.rotate(0.0, 1e4);
        assert_eq!(o.pitch_deg, MAX_PITCH_DEG);
        let mut p = Orbit::of(&Camera::orbit_at(Vec3::ZERO, 0.0, 0.0, 500.0, 30.0));
        // Looking down −Z from +Z: a drag to the right moves the target left (−X).
        p.pan(10.0, 0.0, 1000.0);
        assert!(
            p.target.x < 0.0 && p.target.y.abs() < 1e-4,
            "{:?}",
            p.target
        );
        // One window height of drag moves the target by the view's height there.
        let mut q = Orbit::of(&Camera::orbit_at(Vec3::ZERO, 0.0, 0.0, 500.0, 30.0));
        q.pan(0.0, 1000.0, 1000.0);
        let height = 2.0 * 500.0 * 15f32.to_radians().tan();
        assert!((q.target.y - height).abs() < 1e-2, "{:?}", q.target);
        let mut z = o;
        z.zoom(1.0);
        assert!((z.distance_mm - o.distance_mm / 1.1).abs() < 1e-3);
        assert!((turn_environment(350.0, 100.0) - 20.0).abs() < 1e-4);
    }
}
