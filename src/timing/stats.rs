//! Statistics of one quantity over frames: median, min, max, p90, mean and
//! standard deviation.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A quantity over several frames, in ns.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Stats {
    /// Mean of the two middle values when the count is even.
    pub median_ns: f64,
    pub min_ns: f64,
    pub max_ns: f64,
    /// Nearest rank: the smallest value at least 90 % of the values do not exceed.
    pub p90_ns: f64,
    /// Arithmetic mean (0 in reports older than schema 2).
    #[serde(default)]
    pub mean_ns: f64,
    /// Sample standard deviation (n − 1); 0 for one value.
    #[serde(default)]
    pub std_ns: f64,
}

impl Stats {
    /// `None` for no values; non-finite values are ignored.
    pub fn of(values: &[f64]) -> Option<Stats> {
        let v = sorted(values);
        let n = v.len();
        if n == 0 {
            return None;
        }
        let mean = v.iter().sum::<f64>() / n as f64;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n.max(2) - 1) as f64;
        Some(Stats {
            median_ns: median_of_sorted(&v),
            min_ns: v[0],
            max_ns: v[n - 1],
            p90_ns: v[(9 * n).div_ceil(10) - 1],
            mean_ns: mean,
            std_ns: var.sqrt(),
        })
    }
}

pub fn median(values: &[f64]) -> Option<f64> {
    let v = sorted(values);
    (!v.is_empty()).then(|| median_of_sorted(&v))
}

fn sorted(values: &[f64]) -> Vec<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    v
}

fn median_of_sorted(v: &[f64]) -> f64 {
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn odd_count() {
        let s = Stats::of(&[7.0, 1.0, 3.0, 9.0, 5.0]).unwrap();
        // Sorted 1 3 5 7 9: median the 3rd, p90 rank ⌈4.5⌉ = 5.
        assert_eq!(
            s,
            Stats {
                median_ns: 5.0,
                min_ns: 1.0,
                max_ns: 9.0,
                p90_ns: 9.0,
                mean_ns: 5.0,
                // Σ (x − 5)² = 40 over n − 1 = 4.
                std_ns: 10f64.sqrt(),
            }
        );
    }

    #[test]
    fn even_count_and_p90_rank() {
        // 1..=10 shuffled: median (5 + 6) / 2, p90 rank ⌈9⌉ = 9 → 9.
        let v = [4.0, 10.0, 1.0, 7.0, 2.0, 9.0, 3.0, 8.0, 6.0, 5.0];
        let s = Stats::of(&v).unwrap();
        assert_eq!(s.median_ns, 5.5);
        assert_eq!((s.min_ns, s.max_ns), (1.0, 10.0));
        assert_eq!(s.p90_ns, 9.0);
        // 20 values 1..=20: rank 18. 11 values: rank ⌈9.9⌉ = 10.
        let twenty: Vec<f64> = (1..=20).rev().map(f64::from).collect();
        assert_eq!(Stats::of(&twenty).unwrap().p90_ns, 18.0);
        let eleven: Vec<f64> = (1..=11).map(f64::from).collect();
        assert_eq!(Stats::of(&eleven).unwrap().p90_ns, 10.0);
    }

    #[test]
    fn one_value_empty_and_non_finite() {
        let s = Stats::of(&[42.0]).unwrap();
        assert_eq!([s.median_ns, s.min_ns, s.max_ns, s.p90_ns], [42.0; 4]);
        assert_eq!((s.mean_ns, s.std_ns), (42.0, 0.0));
        assert_eq!(Stats::of(&[]), None);
        assert_eq!(Stats::of(&[f64::NAN]), None);
        assert_eq!(median(&[2.0, f64::INFINITY, 4.0]), Some(3.0));
        assert_eq!(median(&[]), None);
    }
}
