//! A perspective camera in millimetres, with Vulkan's clip conventions
//! (y down, depth 0..1).

use glam::{Mat4, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub position: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub fov_y_deg: f32,
    pub near_mm: f32,
    pub far_mm: f32,
}

impl Camera {
    /// Looks at the centre of `bounds` from the direction given by yaw (about +Y,
    /// 0 = from +Z, the face's front) and pitch (up), far enough that a sphere
    /// around the bounds fills `fill` of the vertical field of view.
    pub fn orbit(
        bounds: (Vec3, Vec3),
        yaw_deg: f32,
        pitch_deg: f32,
        fov_y_deg: f32,
        fill: f32,
    ) -> Self {
        let (lo, hi) = bounds;
        let centre = 0.5 * (lo + hi);
        let radius = 0.5 * (hi - lo).length();
        let half = 0.5 * fov_y_deg.to_radians();
        let distance = radius / (half.sin() * fill.clamp(0.05, 1.0));
        Self::orbit_at(centre, yaw_deg, pitch_deg, distance, fov_y_deg)
    }

    pub fn orbit_at(
        target: Vec3,
        yaw_deg: f32,
        pitch_deg: f32,
        distance_mm: f32,
        fov_y_deg: f32,
    ) -> Self {
        let (yaw, pitch) = (yaw_deg.to_radians(), pitch_deg.to_radians());
        let dir = Vec3::new(
            yaw.sin() * pitch.cos(),
            pitch.sin(),
            yaw.cos() * pitch.cos(),
        );
        Camera {
            position: target + dir * distance_mm,
            target,
            up: Vec3::Y,
            fov_y_deg,
            near_mm: (distance_mm * 0.01).max(0.1),
            far_mm: distance_mm * 10.0,
        }
    }

    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.position, self.target, self.up)
    }

    /// Right-handed perspective for Vulkan clip space: depth in [0, 1], y down.
    pub fn projection(&self, aspect: f32) -> Mat4 {
        glam::camera::rh::proj::vulkan::perspective(
            self.fov_y_deg.to_radians(),
            aspect,
            self.near_mm,
            self.far_mm,
        )
    }

    pub fn view_projection(&self, aspect: f32) -> Mat4 {
        self.projection(aspect) * self.view()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn target_projects_to_the_centre_and_up_is_up_on_screen() {
        let c = Camera::orbit(
            (Vec3::splat(-100.0), Vec3::splat(100.0)),
            30.0,
            10.0,
            30.0,
            0.9,
        );
        let vp = c.view_projection(1.5);
        let centre = vp.project_point3(Vec3::ZERO);
        assert!(centre.x.abs() < 1e-5 && centre.y.abs() < 1e-5);
        assert!((0.0..=1.0).contains(&centre.z));
        // Vulkan: +y in NDC is down the screen, so a point above the target has y < 0.
        assert!(vp.project_point3(Vec3::new(0.0, 50.0, 0.0)).y < 0.0);
        // The bounding sphere (radius √3·100) fills 90% of the vertical field of view.
        let d = (c.position - c.target).length();
        let expected = 173.205 / (15f32.to_radians().sin() * 0.9);
        assert!((d - expected).abs() < 0.01 * expected, "{d} vs {expected}");
    }
}
