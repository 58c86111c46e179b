//! What the skin (and the eyes) look like at a surface point: palette, feature masks,
//! pores, linear albedo and the tangent-space detail normal.

use glam::{Vec2, Vec3};

use super::noise::{fbm, value_noise, worley};
use super::regions::{
    hairline_y, REGION_CHIN, REGION_EARS, REGION_EYES, REGION_FOREHEAD, REGION_LEFT_CHEEK,
    REGION_LOWER_LIP, REGION_NOSE, REGION_RIGHT_CHEEK, REGION_UPPER_LIP,
};
use super::sdf::{fissure, EYE_CENTRE, EYE_RADIUS, STOMION_Y};

/// Colours, sRGB-encoded as authored; converted to linear for blending.
pub(super) struct Palette {
    skin: Vec3,
    flush: Vec3,
    lip: Vec3,
    brow: Vec3,
    hair: Vec3,
    sclera: Vec3,
    iris: Vec3,
    pupil: Vec3,
}

impl Palette {
    pub(super) fn new() -> Self {
        Self {
            // Base skin, sRGB (0.80, 0.58, 0.48) = (204, 148, 122): CIELAB L* ≈ 66,
            // b* ≈ 22, individual typology angle ≈ 36°, i.e. "intermediate" skin
            // (Chardon et al. 1991; Del Bino et al. 2006). Chosen as a mid tone.
            skin: srgb_to_linear(Vec3::new(0.80, 0.58, 0.48)),
            // Flushed (more haemoglobin: green and blue absorbed); artistic.
            flush: srgb_to_linear(Vec3::new(0.80, 0.47, 0.42)),
            // Vermilion; artistic.
            lip: srgb_to_linear(Vec3::new(0.70, 0.38, 0.37)),
            // Dark brown hair for brows and the close-cropped scalp; artistic.
            brow: srgb_to_linear(Vec3::new(0.20, 0.14, 0.10)),
            hair: srgb_to_linear(Vec3::new(0.18, 0.13, 0.10)),
            // Eyes: off-white sclera, brown iris, near-black pupil; artistic.
            sclera: srgb_to_linear(Vec3::new(0.87, 0.83, 0.79)),
            iris: srgb_to_linear(Vec3::new(0.38, 0.25, 0.14)),
            pupil: srgb_to_linear(Vec3::new(0.05, 0.04, 0.04)),
        }
    }
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

fn gauss(p: Vec3, c: Vec3, sigma: f32) -> f32 {
    (-(p - c).length_squared() / (2.0 * sigma * sigma)).exp()
}

/// Whether a (mirrored) surface point lies on the visible part of an eyeball.
fn on_eyeball(q: Vec3) -> bool {
    let d = q - EYE_CENTRE;
    d.z > 0.0 && d.length() < EYE_RADIUS + 0.9 && fissure(d) < 0.2
}

/// Vermilion mask of the lips (0..1), in mirrored coordinates.
fn lip_mask(q: Vec3) -> f32 {
    if q.z < 76.0 {
        return 0.0;
    }
    let tu = (1.0 - (q.x / 25.0).powi(2)).max(0.0);
    let tl = (1.0 - (q.x / 23.0).powi(2)).max(0.0);
    // Cupid's bow: a dip at the midline between two peaks.
    let upper = STOMION_Y + 10.0 * tu.powf(0.45) - 1.3 * (-(q.x / 3.5).powi(2)).exp();
    let lower = STOMION_Y - 9.5 * tl.powf(0.6);
    smoothstep(-0.7, 0.7, upper - q.y) * smoothstep(-0.7, 0.7, q.y - lower)
}

/// Eyebrow mask (0..1): an arch above each eye, thinning laterally.
fn brow_mask(q: Vec3) -> f32 {
    if q.z < 55.0 || q.x < 12.0 || q.x > 54.0 {
        return 0.0;
    }
    let s = (q.x - 13.0) / 40.0;
    let centre = 18.0 + 6.0 * (std::f32::consts::PI * s.clamp(0.0, 1.0)).sin() - 3.0 * s;
    let half = 4.5 - 2.5 * s;
    let ends = smoothstep(12.0, 16.0, q.x) * (1.0 - smoothstep(49.0, 54.0, q.x));
    (1.0 - smoothstep(half - 1.2, half + 0.8, (q.y - centre).abs())) * ends
}

/// Linear-RGB albedo at a surface point.
/// `pore` is the pore mask at the point (see [`pores`]).
pub(super) fn albedo_at(p: Vec3, region: u8, pore: f32, seed: u32, pal: &Palette) -> Vec3 {
    let q = Vec3::new(p.x.abs(), p.y, p.z);
    // Eyeballs (gaze straight ahead along +Z): sclera, iris, pupil.
    let de = q - EYE_CENTRE;
    if on_eyeball(q) {
        let rho = Vec2::new(de.x, de.y).length();
        let ang = de.y.atan2(de.x);
        let fibres = value_noise(Vec3::new(ang * 9.0, rho * 1.5, 0.0), seed ^ 0x1415);
        let iris = pal.iris * (0.8 + 0.35 * fibres) * (1.0 - 0.45 * smoothstep(4.5, 5.9, rho));
        let vessels =
            smoothstep(7.0, 11.0, rho) * smoothstep(0.3, 0.9, fbm(de * 0.8, 3, seed ^ 0x77));
        let sclera = pal.sclera.lerp(pal.flush, 0.35 * vessels);
        let c = sclera.lerp(iris, 1.0 - smoothstep(5.6, 6.1, rho));
        let c = c.lerp(pal.pupil, 1.0 - smoothstep(1.9, 2.3, rho));
        // Shadowed, moist lid margin (and the pink caruncle medially) at the border.
        let margin = smoothstep(-1.8, 0.2, fissure(de));
        return c.lerp(pal.flush * 0.55, margin * 0.8);
    }
    // Skin: slow tone variation (brightness and red/yellow balance).
    let mut c = pal.skin;
    c *= 1.0 + 0.07 * fbm(p / 30.0, 3, seed);
    let hue = fbm(p / 9.0 + Vec3::splat(17.0), 3, seed ^ 0x51);
    c *= Vec3::new(1.0 + 0.04 * hue, 1.0, 1.0 - 0.06 * hue);
    // Flush: cheeks, nose tip, ears, chin; artistic placement.
    let mut red = 0.35 * gauss(q, Vec3::new(42.0, -24.0, 70.0), 17.0)
        + 0.6 * gauss(q, Vec3::new(0.0, -28.0, 110.0), 9.0)
        + 0.25 * gauss(q, Vec3::new(12.0, -33.0, 98.0), 6.0)
        + 0.2 * gauss(q, Vec3::new(0.0, -96.0, 90.0), 12.0);
    if region == REGION_EARS {
        red += 0.45;
    }
    // Blotchy micro-circulation.
    red *= 0.8 + 0.4 * fbm(p / 3.0, 2, seed ^ 0x99);
    c = c.lerp(pal.flush, red.clamp(0.0, 0.85));
    // Lips.
    let lip = lip_mask(q);
    if lip > 0.0 {
        let lines = 1.0 + 0.06 * value_noise(Vec3::new(q.x * 1.8, q.y * 0.25, 0.0), seed ^ 0x3);
        c = c.lerp(pal.lip * lines, lip);
    }
    // The mouth line: a dark crease between the lips.
    if q.z > 80.0 && q.x < 26.0 {
        let crease = (-((q.y - STOMION_Y) / 0.9).powi(2)).exp() * smoothstep(26.0, 20.0, q.x);
        c *= 1.0 - 0.6 * crease;
    }
    // Darker, redder inside the nostrils.
    let nostril = gauss(q, Vec3::new(8.5, -34.5, 95.0), 4.0);
    c = c.lerp(pal.flush * 0.6, (nostril * 1.5).min(0.7));
    // Eyebrows: streaky hairs along the arch.
    let brow = brow_mask(q);
    if brow > 0.0 {
        let strokes = value_noise(
            Vec3::new(q.x * 0.35, q.y * 2.2 - q.x * 0.5, q.z * 0.3),
            seed ^ 0xB,
        );
        c = c.lerp(pal.brow, brow * (0.7 + 0.3 * strokes).clamp(0.0, 1.0));
    }
    // Close-cropped scalp hair above the hairline.
    if region != REGION_EARS {
        let edge = hairline_y(q) + 3.0 * fbm(p / 4.0, 2, seed ^ 0x21);
        let hair = smoothstep(edge - 2.0, edge + 4.0, q.y);
        if hair > 0.0 {
            let strands = 0.75 + 0.25 * value_noise(p * 1.7, seed ^ 0x5);
            c = c.lerp(pal.hair, hair * 0.85 * strands);
        }
    }
    // Pores: small dark dots (not on the vermilion).
    c *= 1.0 - 0.09 * pore * (1.0 - lip);
    // Fine mottling.
    c * (1.0 + 0.03 * value_noise(p / 1.3, seed ^ 0x44))
}

/// Mean spacing of facial pores ≈ 1 mm (artistic; pores are 0.1–0.3 mm wide).
const PORE_CELL_MM: f32 = 0.9;

fn pore_strength(region: u8) -> f32 {
    match region {
        REGION_NOSE | REGION_LEFT_CHEEK | REGION_RIGHT_CHEEK => 1.0,
        REGION_FOREHEAD | REGION_CHIN => 0.8,
        REGION_UPPER_LIP | REGION_LOWER_LIP => 0.5,
        REGION_EYES => 0.3,
        REGION_EARS => 0.4,
        _ => 0.5,
    }
}

/// Pore mask (0..1, 1 at a pore's centre, weighted by region and faded out where a
/// texel of `texel_mm` cannot resolve pores) and its gradient (1/mm).
pub(super) fn pores(p: Vec3, region: u8, texel_mm: f32, seed: u32) -> (f32, Vec3) {
    let strength = pore_strength(region) * smoothstep(0.6, 2.0, PORE_CELL_MM / texel_mm.max(1e-3));
    if strength <= 0.0 {
        return (0.0, Vec3::ZERO);
    }
    let (f1, dir) = worley(p / PORE_CELL_MM, seed ^ 0x9);
    let (a, b) = (0.1, 0.35);
    let t = ((f1 - a) / (b - a)).clamp(0.0, 1.0);
    let value = 1.0 - t * t * (3.0 - 2.0 * t);
    let slope = if t > 0.0 && t < 1.0 {
        -6.0 * t * (1.0 - t) / (b - a)
    } else {
        0.0
    };
    let grad = dir.try_normalize().unwrap_or(Vec3::ZERO) * (slope / PORE_CELL_MM);
    (strength * value, grad * strength)
}

/// Tangent-space detail normal of a small height field (mm): pores 0.05 mm deep,
/// micro relief (≈ 0.05 mm), forehead lines, vertical lip furrows (amplitudes artistic). The slope
/// is taken along T and B; none on the eyeballs.
pub(super) fn detail_normal(
    p: Vec3,
    (t, b): (Vec3, Vec3),
    region: u8,
    texel_mm: f32,
    pore: (f32, Vec3),
    seed: u32,
) -> Vec3 {
    use std::f32::consts::TAU;
    let q = Vec3::new(p.x.abs(), p.y, p.z);
    if on_eyeball(q) {
        return Vec3::Z;
    }
    // Gradient of the height field in 3D (mm/mm).
    let mut grad = pore.1 * -0.05;
    if region == REGION_FOREHEAD {
        let wob = 2.0 * fbm(p / 8.0, 2, seed ^ 0x66);
        let w = TAU / 5.0;
        grad.y += 0.03 * w * (q.y * w + wob).cos() * smoothstep(30.0, 40.0, q.y);
    }
    let lip = lip_mask(q);
    if lip > 0.0 {
        let wob = fbm(p / 2.0, 2, seed ^ 0x67);
        let w = TAU / 1.1;
        grad.x += 0.012 * lip * w * (q.x * w + 4.0 * wob).cos() * p.x.signum();
    }
    let mut dt = grad.dot(t);
    let mut db = grad.dot(b);
    // Micro relief by differences over half a texel (filtered to what the map holds).
    let e = (0.5 * texel_mm).max(0.02);
    let relief = |x: Vec3| {
        0.05 * fbm(x / 2.0, 2, seed ^ 0x1234) + 0.01 * value_noise(x / 0.5, seed ^ 0x4321)
    };
    let h0 = relief(p);
    dt += (relief(p + t * e) - h0) / e;
    db += (relief(p + b * e) - h0) / e;
    Vec3::new(-dt, -db, 1.0).normalize()
}

fn srgb_to_linear(c: Vec3) -> Vec3 {
    c.map(|v| {
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    })
}

pub(super) fn linear_to_srgb(c: Vec3) -> Vec3 {
    c.map(crate::scene::texture::linear_to_srgb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base_skin_tone_is_intermediate_by_ita() {
        // Individual typology angle (Chardon et al. 1991): 28° < ITA ≤ 41° is
        // "intermediate" skin.
        let c = Palette::new().skin;
        let y = c.dot(crate::scene::texture::LUMINANCE);
        let z = (0.0193 * c.x + 0.1192 * c.y + 0.9505 * c.z) / 1.089;
        let f = |t: f32| t.cbrt();
        let l_star = 116.0 * f(y) - 16.0;
        let b_star = 200.0 * (f(y) - f(z));
        let ita = ((l_star - 50.0) / b_star).atan().to_degrees();
        assert!(ita > 28.0 && ita <= 41.0, "ITA {ita}");
    }
}
