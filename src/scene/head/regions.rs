//! Face regions (`REGION_*`) of points on the surface, and the scalp hairline.

use glam::Vec3;

use super::sdf::{ear_local, STOMION_Y};

/// Face regions for the ten specular parameter sets (after the ten-region split of
/// Weyrich et al. 2006, as used in GPU Gems 3 ch. 14). Left/right are the person's.
pub const REGION_FOREHEAD: u8 = 0;
pub const REGION_NOSE: u8 = 1;
pub const REGION_LEFT_CHEEK: u8 = 2;
pub const REGION_RIGHT_CHEEK: u8 = 3;
pub const REGION_CHIN: u8 = 4;
/// Eyelids, the skin around the eyes and the eyeballs.
pub const REGION_EYES: u8 = 5;
/// Upper vermilion and the skin between it and the nose (philtrum).
pub const REGION_UPPER_LIP: u8 = 6;
/// Lower vermilion and the skin just below it.
pub const REGION_LOWER_LIP: u8 = 7;
pub const REGION_EARS: u8 = 8;
/// Scalp, temples behind the cheeks, neck and everything else.
pub const REGION_OTHER: u8 = 9;
pub const REGION_COUNT: usize = 10;
pub const REGION_NAMES: [&str; REGION_COUNT] = [
    "forehead",
    "nose",
    "left cheek",
    "right cheek",
    "chin",
    "eyes",
    "upper lip",
    "lower lip",
    "ears",
    "other",
];

/// Face region of a point on (or near) the surface; see `REGION_*`.
pub fn region_at(p: Vec3) -> u8 {
    let q = Vec3::new(p.x.abs(), p.y, p.z);
    let l = ear_local(q);
    if q.x > 55.0 && l.x > -9.0 && (l.y / 36.0).powi(2) + (l.z / 21.0).powi(2) < 1.0 {
        return REGION_EARS;
    }
    let e = (q - Vec3::new(31.5, 4.0, 78.0)) / Vec3::new(19.0, 12.5, 17.0);
    if e.length_squared() < 1.0 {
        return REGION_EYES;
    }
    // Nose: widens from ≈ 18 mm at the root to the alae.
    if q.z > 76.0 && q.y < 14.0 && q.y > -41.0 {
        let t = ((14.0 - q.y) / 50.0).clamp(0.0, 1.0);
        if q.x < 9.0 + 12.0 * t {
            return REGION_NOSE;
        }
    }
    if q.z > 70.0 && q.x < 27.0 {
        if q.y <= -41.0 && q.y > STOMION_Y {
            return REGION_UPPER_LIP;
        }
        if q.y <= STOMION_Y && q.y > -76.0 {
            return REGION_LOWER_LIP;
        }
    }
    if q.y <= -76.0 && q.y > -125.0 && q.z > 35.0 && q.x < 40.0 {
        return REGION_CHIN;
    }
    if q.y > 14.0 && q.z > 35.0 && q.y < hairline_y(q) {
        return REGION_FOREHEAD;
    }
    if q.z > 10.0 && q.y > -100.0 && q.y <= 20.0 {
        return if p.x >= 0.0 {
            REGION_LEFT_CHEEK
        } else {
            REGION_RIGHT_CHEEK
        };
    }
    REGION_OTHER
}

/// Height (y) of the scalp hairline at a point, by azimuth around the vertical axis
/// (0° = front, 90° = side, 180° = back); artistic, short-haired male pattern.
pub(super) fn hairline_y(q: Vec3) -> f32 {
    const TABLE: [(f32, f32); 11] = [
        (0.0, 80.0),
        (30.0, 75.0),
        (55.0, 56.0),
        (68.0, 40.0),
        (74.0, -4.0),
        (82.0, -6.0),
        (87.0, 26.0),
        (100.0, 30.0),
        (118.0, -20.0),
        (150.0, -48.0),
        (180.0, -52.0),
    ];
    let phi = q.x.atan2(q.z).to_degrees();
    piecewise(&TABLE, phi)
}

fn piecewise(table: &[(f32, f32)], x: f32) -> f32 {
    let mut prev = table[0];
    if x <= prev.0 {
        return prev.1;
    }
    for &(tx, ty) in &table[1..] {
        if x <= tx {
            let t = (x - prev.0) / (tx - prev.0);
            return prev.1 + (ty - prev.1) * t;
        }
        prev = (tx, ty);
    }
    prev.1
}

#[cfg(test)]
mod tests {
    use super::super::tests::head;
    use super::*;

    #[test]
    fn regions_cover_the_face() {
        let h = head();
        let mut seen = [0usize; REGION_COUNT];
        for &r in &h.region_of_vertex {
            seen[r as usize] += 1;
        }
        assert!(seen.iter().all(|&c| c > 20), "{seen:?}");
        assert_eq!(region_at(Vec3::new(0.0, -28.0, 112.0)), REGION_NOSE);
        assert_eq!(region_at(Vec3::new(40.0, -25.0, 75.0)), REGION_LEFT_CHEEK);
        assert_eq!(region_at(Vec3::new(-40.0, -25.0, 75.0)), REGION_RIGHT_CHEEK);
        assert_eq!(region_at(Vec3::new(0.0, 50.0, 85.0)), REGION_FOREHEAD);
        assert_eq!(region_at(Vec3::new(0.0, -95.0, 90.0)), REGION_CHIN);
        assert_eq!(region_at(Vec3::new(0.0, 0.0, -95.0)), REGION_OTHER);
    }
}
