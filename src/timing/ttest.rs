//! Welch's t-test on log-times (Welch 1947): a parametric test that, unlike
//! the rank test, can call a large change significant from 4 samples a side,
//! and the check of its assumption (no sample far out of its side's
//! log-normal scatter) that decides whether it may be used.

/// Iglewicz & Hoaglin's (1993) outlier rule: a modified z-score,
/// 0.6745 (x − median) / MAD, above 3.5 marks an outlier.
const OUTLIER_Z: f64 = 3.5;
/// 0.6745 = Φ⁻¹(0.75): a normal sample's MAD over its standard deviation.
const MAD_TO_SD: f64 = 0.6745;

/// Welch's t-test of the logarithms of two samples of times.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Welch {
    /// mean(ln b) − mean(ln a): the log of the geometric means' ratio.
    pub log_ratio: f64,
    /// Its standard error.
    pub se: f64,
    /// Welch-Satterthwaite degrees of freedom.
    pub df: f64,
    /// Two-sided p-value.
    pub p: f64,
}

impl Welch {
    /// The geometric means' ratio − 1 and its `confidence` interval (t-based,
    /// on the log scale).
    pub fn change(&self, confidence: f64) -> (f64, f64, f64) {
        let t = t_quantile(1.0 - confidence, self.df);
        let rel = |x: f64| x.exp() - 1.0;
        (
            rel(self.log_ratio),
            rel(self.log_ratio - t * self.se),
            rel(self.log_ratio + t * self.se),
        )
    }
}

/// Welch's t-test of the logarithms of `a` and `b` (times, > 0); `None` with
/// fewer than 2 samples a side, a time that is not positive, or no scatter on
/// either side.
pub fn welch_log(a: &[f64], b: &[f64]) -> Option<Welch> {
    let logs = |v: &[f64]| -> Option<Vec<f64>> {
        v.iter()
            .map(|&x| (x > 0.0 && x.is_finite()).then(|| x.ln()))
            .collect()
    };
    let (la, lb) = (logs(a)?, logs(b)?);
    if la.len() < 2 || lb.len() < 2 {
        return None;
    }
    let mean_var = |v: &[f64]| {
        let n = v.len() as f64;
        let m = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0);
        (m, var / n)
    };
    let ((ma, va), (mb, vb)) = (mean_var(&la), mean_var(&lb));
    let se2 = va + vb;
    if se2 <= 0.0 {
        return None;
    }
    let t = (mb - ma) / se2.sqrt();
    let df = se2 * se2 / (va * va / (la.len() as f64 - 1.0) + vb * vb / (lb.len() as f64 - 1.0));
    Some(Welch {
        log_ratio: mb - ma,
        se: se2.sqrt(),
        df,
        p: student_t_two_sided(t, df),
    })
}

/// The t with P(|T| ≥ t) = `p` at `df` degrees of freedom (bisection).
pub fn t_quantile(p: f64, df: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 1.0);
    while student_t_two_sided(hi, df) > p && hi < 1e12 {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if student_t_two_sided(mid, df) > p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Whether the log-times of `a` and `b` look alike enough in shape for the
/// t-test: no sample an outlier (Iglewicz & Hoaglin's modified z-score over
/// 3.5) among the pooled residuals from each side's median. A slow run on one
/// side (a busy machine) fails it; the rank test is used then.
pub fn log_normal_enough(a: &[f64], b: &[f64]) -> bool {
    let residuals = |v: &[f64]| -> Vec<f64> {
        let logs: Vec<f64> = v.iter().filter(|x| **x > 0.0).map(|x| x.ln()).collect();
        let m = median(&logs);
        logs.iter().map(|x| x - m).collect()
    };
    let mut r = residuals(a);
    r.extend(residuals(b));
    if r.len() < 3 {
        return false;
    }
    let abs: Vec<f64> = r.iter().map(|x| x.abs()).collect();
    let mad = median(&abs);
    if mad <= 0.0 {
        // Over half the residuals are 0: any other is an outlier by this rule.
        return r.iter().all(|x| *x == 0.0);
    }
    r.iter().all(|x| MAD_TO_SD * x.abs() / mad <= OUTLIER_Z)
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    match s.len() {
        0 => 0.0,
        n if n % 2 == 1 => s[n / 2],
        n => (s[n / 2 - 1] + s[n / 2]) / 2.0,
    }
}

/// P(|T| ≥ |t|) for Student's t with `df` degrees of freedom:
/// I_{df/(df+t²)}(df/2, 1/2) (Abramowitz & Stegun 26.7.1 with 26.5.27).
pub fn student_t_two_sided(t: f64, df: f64) -> f64 {
    if !t.is_finite() {
        return if t.is_nan() { 1.0 } else { 0.0 };
    }
    let x = df / (df + t * t);
    incomplete_beta(x, df / 2.0, 0.5).clamp(0.0, 1.0)
}

/// The regularized incomplete beta function I_x(a, b), by its continued
/// fraction (modified Lentz), as Numerical Recipes (3rd ed., §6.4) evaluates
/// it.
fn incomplete_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let ln_front = ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln();
    let front = ln_front.exp();
    // The fraction converges fast for x < (a + 1) / (a + b + 2); else by symmetry.
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_fraction(x, a, b) / a
    } else {
        1.0 - front * beta_fraction(1.0 - x, b, a) / b
    }
}

fn beta_fraction(x: f64, a: f64, b: f64) -> f64 {
    const TINY: f64 = 1e-300;
    const EPS: f64 = 1e-15;
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    if d.abs() < TINY {
        d = TINY;
    }
    d = 1.0 / d;
    let mut h = d;
    for m in 1..=300 {
        let m = m as f64;
        let m2 = 2.0 * m;
        let aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 + aa * d;
        if d.abs() < TINY {
            d = TINY;
        }
        c = 1.0 + aa / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        h *= d * c;
        let aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 + aa * d;
        if d.abs() < TINY {
            d = TINY;
        }
        c = 1.0 + aa / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        let del = d * c;
        h *= del;
        if (del - 1.0).abs() < EPS {
            break;
        }
    }
    h
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7, n = 9: the coefficients of Numerical
/// Recipes / Boost's lanczos approximation).
fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Γ(x) Γ(1 − x) = π / sin(πx).
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut sum = C[0];
    for (i, c) in C.iter().enumerate().skip(1) {
        sum += c / (x + i as f64);
    }
    let t = x + G + 0.5;
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + sum.ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn student_t_matches_the_tables() {
        // Two-sided critical values of Student's t (e.g. NIST/SEMATECH
        // e-Handbook, Table 1.4.3.2): df 6: 2.447 at 0.05, 3.707 at 0.01;
        // df 1: 12.706 at 0.05; df 30: 2.042 at 0.05.
        for (t, df, p) in [
            (2.447, 6.0, 0.05),
            (3.707, 6.0, 0.01),
            (12.706, 1.0, 0.05),
            (2.042, 30.0, 0.05),
        ] {
            let got = student_t_two_sided(t, df);
            assert!(
                (got - p).abs() < 2e-4 * p.max(0.01) / 0.01,
                "t {t} df {df}: {got}"
            );
        }
        assert_eq!(student_t_two_sided(0.0, 5.0), 1.0);
        assert_eq!(student_t_two_sided(f64::INFINITY, 5.0), 0.0);
        // Γ(5) = 24, Γ(½) = √π.
        assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-12);
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-12);
    }

    #[test]
    fn welch_on_log_times() {
        // Same shape, one side ×3: far beyond what 4 samples a side need.
        let a = [1.00, 1.05, 0.97, 1.02];
        let b: Vec<f64> = a.iter().map(|x| x * 3.0).collect();
        let w = welch_log(&a, &b).unwrap();
        assert!(w.p < 1e-6, "{w:?}");
        // Equal scatter, 4 a side: df = 6; the ratio is exactly 3.
        assert!((w.df - 6.0).abs() < 1e-9 && (w.log_ratio - 3f64.ln()).abs() < 1e-12);
        let (change, lo, hi) = w.change(0.95);
        assert!((change - 2.0).abs() < 1e-12 && lo < 2.0 && hi > 2.0);
        // The interval is ±t(0.975, 6) = 2.447 standard errors in logs.
        assert!(((hi + 1.0).ln() - w.log_ratio - 2.447 * w.se).abs() < 1e-3 * w.se);
        // The same values: t = 0.
        assert_eq!(welch_log(&a, &a).unwrap().p, 1.0);
        // Scale-free: ×1000 on both sides changes nothing.
        let a3: Vec<f64> = a.iter().map(|x| x * 1000.0).collect();
        let b3: Vec<f64> = b.iter().map(|x| x * 1000.0).collect();
        assert!((welch_log(&a3, &b3).unwrap().p - w.p).abs() < 1e-12);
        // Too few or bad samples, or no scatter: no test.
        assert_eq!(welch_log(&[1.0], &[2.0, 3.0]), None);
        assert_eq!(welch_log(&[1.0, 0.0], &[2.0, 3.0]), None);
        assert_eq!(welch_log(&[1.0, 1.0], &[2.0, 2.0]), None);
    }

    #[test]
    fn one_far_run_fails_the_shape_check() {
        let a = [1.00, 1.05, 0.97, 1.02];
        let b = [3.0, 3.1, 2.95, 3.05];
        assert!(log_normal_enough(&a, &b));
        // One run 40 % slower than its side (a busy machine).
        assert!(!log_normal_enough(&[1.00, 1.05, 0.97, 1.40], &b));
        assert!(!log_normal_enough(&[1.0], &[2.0]));
    }
}
