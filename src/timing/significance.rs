//! Whether two samples differ: the Mann-Whitney U test (two-sided; Google
//! Benchmark's `tools/compare.py` uses it over repetitions) and Holm's
//! step-down correction for testing many passes at once (Holm 1979).

/// The two-sided p-value of the Mann-Whitney U test of `a` against `b`:
/// exact (the U distribution counted by recursion) when there are no ties
/// and `a.len() × b.len() ≤ 10 000`, else the normal approximation with the
/// tie correction and a continuity correction of ½ (as SciPy's
/// `mannwhitneyu(method="asymptotic")`). 1 when either sample is empty.
pub fn mann_whitney_p(a: &[f64], b: &[f64]) -> f64 {
    p_value(a, b, false)
}

fn p_value(a: &[f64], b: &[f64], asymptotic: bool) -> f64 {
    let (n1, n2) = (a.len(), b.len());
    if n1 == 0 || n2 == 0 {
        return 1.0;
    }
    // Ranks of the pooled samples, ties given their mean rank.
    let mut pooled: Vec<(f64, usize)> = a
        .iter()
        .map(|&v| (v, 0))
        .chain(b.iter().map(|&v| (v, 1)))
        .collect();
    pooled.sort_by(|x, y| x.0.total_cmp(&y.0));
    let n = pooled.len();
    let mut rank_sum_a = 0.0;
    let mut tie_term = 0.0; // Σ (t³ − t) over groups of ties
    let mut i = 0;
    while i < n {
        let mut j = i;
        while j + 1 < n && pooled[j + 1].0 == pooled[i].0 {
            j += 1;
        }
        let t = (j - i + 1) as f64;
        let rank = (i + j) as f64 / 2.0 + 1.0;
        rank_sum_a += rank * pooled[i..=j].iter().filter(|p| p.1 == 0).count() as f64;
        tie_term += t * t * t - t;
        i = j + 1;
    }
    let (n1f, n2f) = (n1 as f64, n2 as f64);
    let u1 = rank_sum_a - n1f * (n1f + 1.0) / 2.0;
    let mean = n1f * n2f / 2.0;
    if !asymptotic && tie_term == 0.0 && n1 * n2 <= 10_000 {
        return exact_two_sided(u1, n1, n2);
    }
    let nf = n as f64;
    let var = n1f * n2f / 12.0 * ((nf + 1.0) - tie_term / (nf * (nf - 1.0)));
    if var <= 0.0 {
        // Every value equal: no evidence of a difference.
        return 1.0;
    }
    let z = ((u1 - mean).abs() - 0.5).max(0.0) / var.sqrt();
    (2.0 * normal_sf(z)).min(1.0)
}

/// P(|U − mean| ≥ |u − mean|) under the null, counting the arrangements of
/// n1 + n2 distinct values: c(i, j, u) = c(i−1, j, u−j) + c(i, j−1, u).
fn exact_two_sided(u: f64, n1: usize, n2: usize) -> f64 {
    let max_u = n1 * n2;
    // counts[j][u] for the current i, arrangements of i a's and j b's.
    let mut prev: Vec<Vec<f64>> = (0..=n2)
        .map(|_| {
            let mut v = vec![0.0; max_u + 1];
            v[0] = 1.0;
            v
        })
        .collect();
    for i in 1..=n1 {
        let mut cur = vec![vec![0.0; max_u + 1]; n2 + 1];
        cur[0][0] = 1.0;
        for j in 1..=n2 {
            for v in 0..=i * j {
                let from_a = if v >= j { prev[j][v - j] } else { 0.0 };
                cur[j][v] = from_a + cur[j - 1][v];
            }
        }
        prev = cur;
    }
    let counts = &prev[n2];
    let total: f64 = counts.iter().sum();
    let mean = max_u as f64 / 2.0;
    let d = (u - mean).abs();
    let tail: f64 = counts
        .iter()
        .enumerate()
        .filter(|(v, _)| (*v as f64 - mean).abs() >= d - 1e-9)
        .map(|(_, c)| c)
        .sum();
    (tail / total).min(1.0)
}

/// The standard normal's upper tail, 1 − Φ(z), from erfc (W. J. Cody's
/// rational approximation as in Numerical Recipes' `erfcc`, |error| < 1.2e-7).
pub fn normal_sf(z: f64) -> f64 {
    0.5 * erfc(z / std::f64::consts::SQRT_2)
}

fn erfc(x: f64) -> f64 {
    // Numerical Recipes in C, 2nd ed., §6.2 (erfcc): the polynomial's
    // coefficients after the first, summed by Horner's rule as there.
    const C: [f64; 9] = [
        1.000_023_68,
        0.374_091_96,
        0.096_784_18,
        -0.186_288_06,
        0.278_868_07,
        -1.135_203_98,
        1.488_515_87,
        -0.822_152_23,
        0.170_872_77,
    ];
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let horner = C.iter().rev().fold(0.0, |acc, &c| c + t * acc);
    let r = t * (-z * z - 1.265_512_23 + t * horner).exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

/// Holm's step-down adjusted p-values, in the input's order: sorted
/// ascending, p₍ᵢ₎ × (m − i) (i from 0), made non-decreasing, capped at 1.
/// Rejecting where the adjusted value is below α keeps the family-wise error
/// rate at α.
pub fn holm(p: &[f64]) -> Vec<f64> {
    let m = p.len();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| p[a].total_cmp(&p[b]));
    let mut adjusted = vec![1.0; m];
    let mut running: f64 = 0.0;
    for (i, &k) in order.iter().enumerate() {
        running = running.max(((m - i) as f64 * p[k]).min(1.0));
        adjusted[k] = running;
    }
    adjusted
}

/// The smallest two-sided p-value the exact test can give with n and n
/// samples and no ties: 2 / C(2n, n).
pub fn smallest_p(n: usize) -> f64 {
    let mut c = 1.0;
    for k in 0..n {
        c = c * (2 * n - k) as f64 / (k + 1) as f64;
    }
    (2.0 / c).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn exact_counts_small_samples_by_hand() {
        // 3 vs 3, fully separated: U = 0 is 1 of C(6,3) = 20 arrangements,
        // two-sided 2/20.
        assert!(close(
            mann_whitney_p(&[1.0, 2.0, 3.0], &[4.0, 5.0, 6.0]),
            0.1,
            1e-12
        ));
        assert!(close(
            mann_whitney_p(&[4.0, 5.0, 6.0], &[1.0, 2.0, 3.0]),
            0.1,
            1e-12
        ));
        // 2 vs 2 interleaved a b a b: U_a = 1 (one b below an a). The null U
        // over C(4,2) = 6 arrangements is 0,1,2,2,3,4; |U − 2| ≥ 1 for four
        // of them: p = 4/6.
        assert!(close(
            mann_whitney_p(&[1.0, 3.0], &[2.0, 4.0]),
            4.0 / 6.0,
            1e-12
        ));
        // 4 vs 4 with U = 1: P(U ≤ 1) = 2/70 (U = 0 and U = 1 each once), two-sided 4/70.
        assert!(close(
            mann_whitney_p(&[1.0, 2.0, 3.0, 5.0], &[4.0, 6.0, 7.0, 8.0]),
            4.0 / 70.0,
            1e-12
        ));
        assert_eq!(mann_whitney_p(&[], &[1.0]), 1.0);
        assert!(close(smallest_p(3), 0.1, 1e-12));
        assert!(close(smallest_p(5), 2.0 / 252.0, 1e-12));
    }

    #[test]
    fn normal_approximation_with_ties() {
        // a = 1,2,2,3, b = 2,3,3,4 (ties): pooled ranks 1, 3,3,3, 6,6,6, 8;
        // rank sum of a = 1 + 3 + 3 + 6 = 13, U = 13 − 10 = 3, mean 8;
        // ties: groups of 3 and 3 → Σ(t³ − t) = 48; var = 16/12 × (9 − 48/56)
        // = 10.857; z = (5 − 0.5)/3.2950 = 1.3657; p = 2 × (1 − Φ(1.3657)) = 0.1720
        // (SciPy: 0.1720337089218229).
        let p = mann_whitney_p(&[1.0, 2.0, 2.0, 3.0], &[2.0, 3.0, 3.0, 4.0]);
        assert!(close(p, 0.172_033_708_921_822_9, 1e-6), "{p}");
        // All equal: no evidence.
        assert_eq!(mann_whitney_p(&[1.0; 5], &[1.0; 5]), 1.0);
        // Φ at known points: 1 − Φ(1.959964) = 0.025.
        assert!(close(normal_sf(1.959_964), 0.025, 1e-6));
        assert!(close(normal_sf(-1.0), 0.841_344_7, 1e-6));
    }

    #[test]
    fn both_methods_match_scipy() {
        // SciPy 1.x: mannwhitneyu(a, b, method="exact") = 0.12768789966259345,
        // method="asymptotic" (continuity-corrected) = 0.12602212177037309.
        let a: Vec<f64> = (0..12).map(|i| i as f64 * 2.0).collect();
        let b: Vec<f64> = (0..12).map(|i| i as f64 * 2.0 + 5.0).collect();
        assert!(close(
            mann_whitney_p(&a, &b),
            0.127_687_899_662_593_45,
            1e-12
        ));
        assert!(close(p_value(&a, &b, true), 0.126_022_121_770_373_09, 1e-6));
    }

    #[test]
    fn holm_by_hand() {
        // p = 0.01, 0.04, 0.03, 0.005 (m = 4): sorted 0.005 0.01 0.03 0.04 →
        // × 4, 3, 2, 1 = 0.02, 0.03, 0.06, 0.04 → monotone 0.02 0.03 0.06 0.06.
        let adj = holm(&[0.01, 0.04, 0.03, 0.005]);
        let want = [0.03, 0.06, 0.06, 0.02];
        for (a, w) in adj.iter().zip(want) {
            assert!(close(*a, w, 1e-12), "{adj:?}");
        }
        // Capped at 1; one test is unchanged.
        assert_eq!(holm(&[0.6, 0.9]), vec![1.0, 1.0]);
        assert_eq!(holm(&[0.2]), vec![0.2]);
        assert!(holm(&[]).is_empty());
    }
}
