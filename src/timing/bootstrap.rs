//! A bootstrap confidence interval of the relative change of the median
//! between two samples (criterion.rs reports the change this way): each side
//! resampled with replacement, the change median(new*) / median(base*) − 1
//! computed per resample, the interval its percentiles. Seeded, so a report
//! compared twice gives the same interval.

use super::stats::median;

/// Resamples per interval (criterion.rs's default `nresamples` is 100 000;
/// 10 000 keeps the 2.5 % percentile to about ±0.2 % of its rank).
pub const RESAMPLES: usize = 10_000;

/// The point estimate and the two-sided `level` (e.g. 0.95) percentile
/// interval of median(new) / median(base) − 1; `None` when either side has no
/// finite value or the base median is not positive.
pub fn relative_change_ci(base: &[f64], new: &[f64], level: f64) -> Option<(f64, f64, f64)> {
    let estimate = median(new)? / positive(median(base)?)? - 1.0;
    let mut rng = SplitMix64(0x5eed_d3a1_5c0f_fee5 ^ (base.len() as u64) << 32 ^ new.len() as u64);
    let mut a = vec![0.0; base.len()];
    let mut b = vec![0.0; new.len()];
    let mut changes = Vec::with_capacity(RESAMPLES);
    for _ in 0..RESAMPLES {
        resample(base, &mut a, &mut rng);
        resample(new, &mut b, &mut rng);
        if let (Some(mb), Some(mn)) = (median(&a).and_then(positive), median(&b)) {
            changes.push(mn / mb - 1.0);
        }
    }
    changes.sort_by(f64::total_cmp);
    let tail = (1.0 - level) / 2.0;
    let at = |q: f64| changes[((q * changes.len() as f64) as usize).min(changes.len() - 1)];
    (!changes.is_empty()).then(|| (estimate, at(tail), at(1.0 - tail)))
}

fn positive(v: f64) -> Option<f64> {
    (v > 0.0).then_some(v)
}

fn resample(from: &[f64], into: &mut [f64], rng: &mut SplitMix64) {
    for v in into.iter_mut() {
        *v = from[(rng.next() % from.len() as u64) as usize];
    }
}

/// Steele, Lea & Flood's SplitMix64 (2014): enough for resampling indices.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shift_with_small_noise_is_bracketed() {
        // Base 100 ± 1, new 120 ± 1: change +20 %, interval within a few tenths.
        let base: Vec<f64> = (0..20)
            .map(|i| 100.0 + (i % 5) as f64 * 0.5 - 1.0)
            .collect();
        let new: Vec<f64> = base.iter().map(|v| v * 1.2).collect();
        let (est, lo, hi) = relative_change_ci(&base, &new, 0.95).unwrap();
        assert!((est - 0.2).abs() < 1e-12, "{est}");
        assert!(lo <= est && est <= hi, "{lo} {est} {hi}");
        assert!(lo > 0.18 && hi < 0.22, "{lo} {hi}");
    }

    #[test]
    fn identical_samples_bracket_zero_and_repeat() {
        let v: Vec<f64> = (0..15).map(|i| 50.0 + ((i * 7) % 11) as f64).collect();
        let (est, lo, hi) = relative_change_ci(&v, &v, 0.95).unwrap();
        assert_eq!(est, 0.0);
        assert!(lo < 0.0 && hi > 0.0, "{lo} {hi}");
        assert_eq!(relative_change_ci(&v, &v, 0.95), Some((est, lo, hi)));
    }

    #[test]
    fn empty_or_zero_bases_give_none() {
        assert_eq!(relative_change_ci(&[], &[1.0], 0.95), None);
        assert_eq!(relative_change_ci(&[0.0, 0.0], &[1.0], 0.95), None);
    }
}
