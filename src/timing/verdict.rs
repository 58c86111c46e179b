//! A pass's verdict from its two samples (docs/guide/compare-in-ci.md, "Comparing
//! runs"): the test and interval that fit the samples, then criterion.rs's rule
//! — a change counts only when it is significant after Holm's correction
//! **and** its whole interval lies beyond the noise threshold — with Chromium
//! Pinpoint's third answer, inconclusive (and how many more samples).
//!
//! The test: Welch's t on log-times, so that a large change is significant
//! from 4 runs a side (the Mann-Whitney U test's exact p-value of n against n
//! cannot go below 2 / C(2n, n), 0.029 at 4). Its assumption, log-times that
//! scatter normally, is checked: a run that stands out is flagged. Such a run
//! widens the interval and lowers t, so it costs power, not false alarms. The
//! rank test remains where the t-test is undefined (no scatter on either side,
//! a time that is not positive).

use super::bootstrap::relative_change_ci;
use super::significance::{mann_whitney_p, smallest_p};
use super::ttest::{log_normal_enough, welch_log};
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    Regressed,
    Improved,
    Unchanged,
    /// The interval straddles the threshold, or too few samples to be
    /// significant: measure more.
    Inconclusive,
}

impl Verdict {
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Regressed => "regressed",
            Verdict::Improved => "improved",
            Verdict::Unchanged => "unchanged",
            Verdict::Inconclusive => "inconclusive",
        }
    }
}

/// Which test gave a pass's p-value and interval.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Test {
    /// Welch's t on log-times; the change is the geometric means' ratio, its
    /// interval t-based.
    WelchLog,
    /// Mann-Whitney U; the change is the medians' ratio, its interval the
    /// bootstrap's.
    MannWhitney,
}

impl Test {
    /// A short name for tables.
    pub fn short(self) -> &'static str {
        match self {
            Test::WelchLog => "t",
            Test::MannWhitney => "U",
        }
    }
}

/// The evidence of one pass: the test used, the relative change with its
/// interval, and the (uncorrected) p-value.
#[derive(Clone, Copy, Debug)]
pub struct Evidence {
    pub test: Test,
    /// (change, low, high) as new/base − 1.
    pub change: Option<(f64, f64, f64)>,
    pub p: f64,
    /// A sample stands out of its side's log-normal scatter (the t-test's
    /// assumption in doubt; ttest::log_normal_enough).
    pub outlier: bool,
}

/// The evidence of samples `base` and `new` (times or ratios, > 0).
pub fn evidence(base: &[f64], new: &[f64], confidence: f64) -> Evidence {
    match welch_log(base, new) {
        Some(w) => Evidence {
            test: Test::WelchLog,
            change: Some(w.change(confidence)),
            p: w.p,
            outlier: !log_normal_enough(base, new),
        },
        None => Evidence {
            test: Test::MannWhitney,
            change: relative_change_ci(base, new, confidence),
            p: mann_whitney_p(base, new),
            outlier: false,
        },
    }
}

/// criterion.rs's rule: significant (`p_holm` < `significance`) and the whole
/// interval beyond ±`threshold`; unchanged when the interval lies within it.
pub fn verdict(change: (f64, f64, f64), p_holm: f64, threshold: f64, significance: f64) -> Verdict {
    let (_, lo, hi) = change;
    let significant = p_holm < significance;
    if significant && lo > threshold {
        Verdict::Regressed
    } else if significant && hi < -threshold {
        Verdict::Improved
    } else if lo >= -threshold && hi <= threshold {
        Verdict::Unchanged
    } else {
        Verdict::Inconclusive
    }
}

/// For an inconclusive pass with `n` samples a side: about how many more a
/// side would decide it, `None` where no number would (the change sits on the
/// threshold). The interval shrinks as 1/√n: the n at which it would clear the
/// threshold on the side the estimate is on; with the rank test also the n at
/// which its exact p-value could reach `significance / family`.
pub fn more_samples(
    test: Test,
    n: usize,
    change: (f64, f64, f64),
    threshold: f64,
    significance: f64,
    family: usize,
) -> Option<usize> {
    let (est, lo, hi) = change;
    let n = n.max(1);
    let half = (hi - lo) / 2.0;
    let margin = (est.abs() - threshold).abs();
    if margin < 0.1 * threshold.max(1e-3) {
        return None;
    }
    let mut needed = (n as f64 * (half / margin).powi(2)).ceil() as usize;
    if est.abs() > threshold && test == Test::MannWhitney {
        let per_test = significance / family.max(1) as f64;
        let mut k = n.max(2);
        while smallest_p(k) >= per_test && k < 1000 {
            k += 1;
        }
        needed = needed.max(k);
    }
    Some(needed.saturating_sub(n).clamp(1, 100_000))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_outlying_run_is_flagged_and_costs_power() {
        let a = [1.00, 1.05, 0.97, 1.02];
        let b = [3.0, 3.1, 2.95, 3.05];
        let e = evidence(&a, &b, 0.95);
        assert_eq!((e.test, e.outlier), (Test::WelchLog, false));
        assert!(e.p < 1e-5, "{e:?}");
        let (c, lo, hi) = e.change.unwrap();
        assert!(lo < c && c < hi && lo > 1.5, "{e:?}");
        // One run far out: flagged; t falls and the interval widens.
        let far = evidence(&[1.00, 1.05, 0.97, 1.60], &b, 0.95);
        assert_eq!((far.test, far.outlier), (Test::WelchLog, true));
        let (_, far_lo, far_hi) = far.change.unwrap();
        assert!(far.p > e.p && far_hi - far_lo > hi - lo, "{far:?} vs {e:?}");
        // No scatter at all: the rank test (with ties: its normal approximation).
        let flat = evidence(&[1.0, 1.0], &[2.0, 2.0], 0.95);
        assert_eq!(flat.test, Test::MannWhitney);
        assert!(flat.p > 0.05, "{flat:?}");
    }

    #[test]
    fn the_rule() {
        let t = 0.06;
        assert_eq!(verdict((0.5, 0.3, 0.7), 0.01, t, 0.05), Verdict::Regressed);
        assert_eq!(
            verdict((0.5, 0.3, 0.7), 0.2, t, 0.05),
            Verdict::Inconclusive
        );
        assert_eq!(
            verdict((-0.5, -0.7, -0.3), 0.01, t, 0.05),
            Verdict::Improved
        );
        assert_eq!(
            verdict((0.0, -0.05, 0.05), 0.9, t, 0.05),
            Verdict::Unchanged
        );
        // Significant but the interval reaches into the threshold.
        assert_eq!(
            verdict((0.1, 0.05, 0.15), 0.001, t, 0.05),
            Verdict::Inconclusive
        );
        // A rank test with 4 a side over 16 passes needs 2/C(2k, k) < 0.05/16: k = 6.
        let more = more_samples(Test::MannWhitney, 4, (0.5, 0.2, 0.8), t, 0.05, 16);
        assert_eq!(more, Some(2));
        assert_eq!(
            more_samples(Test::WelchLog, 4, (0.5, 0.2, 0.8), t, 0.05, 16),
            Some(1)
        );
        assert_eq!(
            more_samples(Test::WelchLog, 4, (0.06, -0.1, 0.2), t, 0.05, 16),
            None
        );
    }
}
