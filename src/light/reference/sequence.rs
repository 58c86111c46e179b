//! Deterministic random numbers for the estimators: SplitMix64 (Steele, Lea &
//! Flood, "Fast splittable pseudorandom number generators", OOPSLA 2014), one
//! stream per shaded point, and jittered strata drawn from it.

use glam::Vec2;

/// A SplitMix64 stream.
pub struct Rng(u64);

impl Rng {
    /// The stream of `seed` (distinct seeds give unrelated streams).
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    /// Uniform in `[0, 1)` (24 bits).
    pub fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 40) as f32 * (1.0 / 16_777_216.0)
    }

    /// A uniform point in cell `k` of a `side × side` grid over `[0, 1)²`.
    pub fn jittered(&mut self, k: u32, side: u32) -> Vec2 {
        let cell = Vec2::new((k % side) as f32, (k / side) as f32);
        let p = (cell + Vec2::new(self.next(), self.next())) / side as f32;
        // (side − 1 + 0.99999994) / side may round up to 1.
        p.min(Vec2::splat(1.0 - f32::EPSILON / 2.0))
    }
}
