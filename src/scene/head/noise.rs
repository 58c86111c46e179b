//! Noise (hash-based, deterministic): value noise, fBm and Worley F1.

use glam::Vec3;

fn hash3(x: i32, y: i32, z: i32, seed: u32) -> u32 {
    let mut h = seed ^ 0x9E37_79B9;
    h = (h ^ x as u32).wrapping_mul(0x85EB_CA6B);
    h = (h ^ y as u32).wrapping_mul(0xC2B2_AE35);
    h = (h ^ z as u32).wrapping_mul(0x27D4_EB2F);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2C1B_3C6D);
    h ^= h >> 12;
    h = h.wrapping_mul(0x297A_2D39);
    h ^ (h >> 15)
}

fn unit(h: u32) -> f32 {
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// Value noise in [−1, 1] with quintic interpolation.
pub(super) fn value_noise(p: Vec3, seed: u32) -> f32 {
    let i = p.floor();
    let f = p - i;
    let u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    let (x, y, z) = (i.x as i32, i.y as i32, i.z as i32);
    let c = |dx: i32, dy: i32, dz: i32| unit(hash3(x + dx, y + dy, z + dz, seed)) * 2.0 - 1.0;
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x00 = lerp(c(0, 0, 0), c(1, 0, 0), u.x);
    let x10 = lerp(c(0, 1, 0), c(1, 1, 0), u.x);
    let x01 = lerp(c(0, 0, 1), c(1, 0, 1), u.x);
    let x11 = lerp(c(0, 1, 1), c(1, 1, 1), u.x);
    lerp(lerp(x00, x10, u.y), lerp(x01, x11, u.y), u.z)
}

/// Fractal sum of value noise, normalised to about [−1, 1].
pub(super) fn fbm(p: Vec3, octaves: u32, seed: u32) -> f32 {
    let (mut sum, mut amp, mut norm, mut freq) = (0.0, 1.0, 0.0, 1.0);
    for o in 0..octaves {
        sum += amp * value_noise(p * freq, seed.wrapping_add(o * 1013));
        norm += amp;
        amp *= 0.5;
        freq *= 2.03;
    }
    sum / norm
}

/// Worley F1: distance (cell units) to the nearest jittered feature point, and the
/// vector from that point to `p`.
pub(super) fn worley(p: Vec3, seed: u32) -> (f32, Vec3) {
    let i = p.floor();
    let (x, y, z) = (i.x as i32, i.y as i32, i.z as i32);
    let mut best = (f32::MAX, Vec3::ZERO);
    for dz in -1..=1 {
        for dy in -1..=1 {
            for dx in -1..=1 {
                let h = hash3(x + dx, y + dy, z + dz, seed);
                let j = Vec3::new(
                    (h & 1023) as f32,
                    ((h >> 10) & 1023) as f32,
                    ((h >> 20) & 1023) as f32,
                ) / 1024.0;
                let v = p - (Vec3::new((x + dx) as f32, (y + dy) as f32, (z + dz) as f32) + j);
                let d2 = v.length_squared();
                if d2 < best.0 {
                    best = (d2, v);
                }
            }
        }
    }
    (best.0.sqrt(), best.1)
}
