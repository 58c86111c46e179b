//! The verdict rule on synthetic interleaved measurements with this
//! machine's noise: a pass made 3× slower is called regressed from 4 runs a
//! side, and 20 A/A pairs at 4 and at 10 runs a side give no false alarm
//! (docs/guide/compare-in-ci.md, "Comparing runs").

use super::regression::{
    compare, table, CompareOptions, Comparison, MeasuredFrame, Measurement, PassChange, Test,
    Verdict, FRAME_ROW,
};
use super::run::RULER_COPY;
use std::collections::BTreeMap;

fn row<'a>(c: &'a Comparison, name: &str) -> &'a PassChange {
    c.passes.iter().find(|p| p.name == name).unwrap()
}

/// splitmix64: a seeded stream of uniform numbers in [0, 1).
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A standard normal (Box-Muller).
    fn normal(&mut self) -> f64 {
        let u = self.uniform().max(1e-300);
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * self.uniform()).cos()
    }
}

/// The default frame's passes at 512² on lavapipe, roughly (ms; docs/
/// performance.md's tables): 15 passes from 0.3 to 600 ms, and the ruler.
const FRAME: [(&str, f64); 15] = [
    ("stretch", 40.0),
    ("irradiance", 600.0),
    ("blur1", 60.0),
    ("blur2", 45.0),
    ("blur3", 15.0),
    ("blur4", 8.0),
    ("blur5", 5.0),
    ("blur6", 4.0),
    ("skin_depth", 30.0),
    ("background", 25.0),
    ("skin", 70.0),
    ("meter", 1.0),
    ("meter_reduce", 0.3),
    ("tonemap", 2.0),
    ("readback", 0.5),
];

/// One side of an interleaved measurement of [`FRAME`] with the noise of
/// this 2-core machine under load (docs/guide/compare-in-ci.md, "Comparing runs":
/// runs move ±10 % quiet to ±25 % busy; a pass's runs scatter ±20–30 %):
/// per run a machine load shared by every pass and the ruler (log-normal,
/// σ 0.12) that one run in ten meets busier still (×1.4); per run and pass
/// σ 0.06 of its own (0.15 under 5 ms, on a host clock that jitters); per
/// frame σ 0.04. `slow` scales one pass.
fn interleaved(
    rng: &mut Rng,
    runs: usize,
    frames: usize,
    slow: Option<(&str, f64)>,
) -> Measurement {
    let mut m = Measurement {
        source: "synthetic".into(),
        pass_order: FRAME.iter().map(|p| p.0.to_string()).collect(),
        ..Default::default()
    };
    m.pass_order.push(RULER_COPY.into());
    for r in 0..runs {
        let busy = if rng.uniform() < 0.1 {
            1.4f64.ln()
        } else {
            0.0
        };
        let load = 0.12 * rng.normal() + busy;
        let mut own: Vec<f64> = FRAME
            .iter()
            .map(|(_, ms)| if *ms < 5.0 { 0.15 } else { 0.06 } * rng.normal())
            .collect();
        own.push(0.06 * rng.normal());
        for _ in 0..frames {
            let mut passes = BTreeMap::new();
            for (k, (name, ms)) in FRAME.iter().chain([(RULER_COPY, 2.0)].iter()).enumerate() {
                let scale = match slow {
                    Some((s, x)) if s == *name => x,
                    _ => 1.0,
                };
                let log = load + own[k] + 0.04 * rng.normal();
                passes.insert(name.to_string(), ms * 1e6 * scale * log.exp());
            }
            m.frames.push(MeasuredFrame {
                run: format!("run{r}"),
                passes,
            });
        }
    }
    m
}

fn alarms(c: &Comparison) -> usize {
    c.count(Verdict::Regressed) + c.count(Verdict::Improved)
}

#[test]
fn a_threefold_pass_is_regressed_with_four_runs_a_side() {
    // 20 draws of the machine's noise; each time only blur3 (15 ms) × 3.
    let mut rng = Rng(44);
    for draw in 0..20 {
        let base = interleaved(&mut rng, 4, 2, None);
        let new = interleaved(&mut rng, 4, 2, Some(("blur3", 3.0)));
        let c = compare(&base, &new, &CompareOptions::default()).unwrap();
        let blur3 = row(&c, "blur3");
        assert_eq!(
            blur3.verdict,
            Verdict::Regressed,
            "draw {draw}:\n{}",
            table(&c)
        );
        assert_eq!(c.count(Verdict::Improved), 0, "draw {draw}:\n{}", table(&c));
        let others = c.count(Verdict::Regressed) - 1;
        let frame = usize::from(row(&c, FRAME_ROW).verdict == Verdict::Regressed);
        assert_eq!(
            others,
            frame,
            "draw {draw}: another pass regressed:\n{}",
            table(&c)
        );
    }
}

#[test]
fn a_a_pairs_give_no_false_alarm() {
    // 20 A/A pairs at 4 and at 10 runs a side (2 measured frames each, as
    // `dermis interleave`'s default), every pass judged.
    for (runs, seed) in [(4, 1000), (10, 2000)] {
        let mut rng = Rng(seed);
        let (mut rows, mut welch, mut flagged) = (0, 0, 0);
        for pair in 0..20 {
            let a = interleaved(&mut rng, runs, 2, None);
            let b = interleaved(&mut rng, runs, 2, None);
            let c = compare(&a, &b, &CompareOptions::default()).unwrap();
            assert_eq!(alarms(&c), 0, "{runs} runs, pair {pair}:\n{}", table(&c));
            rows += c.passes.iter().filter(|p| p.judged).count();
            welch += c
                .passes
                .iter()
                .filter(|p| p.judged && p.test == Test::WelchLog)
                .count();
            flagged += c.passes.iter().filter(|p| p.judged && p.outlier).count();
        }
        // The parametric test did the judging (the rank test cannot alarm at
        // 4), busy runs included.
        assert_eq!(welch, rows, "{runs} runs");
        assert!(flagged > 0, "{runs} runs: no busy run was flagged");
        eprintln!("{runs} runs a side: {rows} rows, {flagged} with a run that stands out");
    }
}

#[test]
fn named_passes_alone_are_judged() {
    let mut rng = Rng(5);
    let base = interleaved(&mut rng, 4, 2, None);
    let new = interleaved(&mut rng, 4, 2, Some(("blur3", 3.0)));
    let opts = CompareOptions {
        passes: vec!["blur3".into()],
        ..Default::default()
    };
    let c = compare(&base, &new, &opts).unwrap();
    let judged: Vec<&str> = c
        .passes
        .iter()
        .filter(|p| p.judged)
        .map(|p| p.name.as_str())
        .collect();
    assert_eq!(judged, ["blur3", FRAME_ROW]);
    assert_eq!(row(&c, "blur3").verdict, Verdict::Regressed);
    assert!(table(&c).contains("not in --passes"), "{}", table(&c));
    let bad = CompareOptions {
        passes: vec!["blur9".into()],
        ..Default::default()
    };
    let e = compare(&base, &new, &bad).unwrap_err();
    assert!(e.to_string().contains("--passes: \"blur9\""), "{e}");
}

/// The study at scale: the share of A/A pairs with a false alarm and of 3×
/// draws found, over many draws (`cargo test --release --lib aa_rates --
/// --ignored --nocapture`).
#[test]
#[ignore]
fn aa_rates() {
    for runs in [4, 10] {
        let mut rng = Rng(99 + runs as u64);
        let (mut alarmed, mut found, n) = (0, 0, 500);
        for _ in 0..n {
            let a = interleaved(&mut rng, runs, 2, None);
            let b = interleaved(&mut rng, runs, 2, None);
            alarmed +=
                usize::from(alarms(&compare(&a, &b, &CompareOptions::default()).unwrap()) > 0);
            let s = interleaved(&mut rng, runs, 2, Some(("blur3", 3.0)));
            let c = compare(&a, &s, &CompareOptions::default()).unwrap();
            found += usize::from(row(&c, "blur3").verdict == Verdict::Regressed);
        }
        eprintln!(
            "{runs} runs a side: A/A pairs with a false alarm {alarmed}/{n}, 3x found {found}/{n}"
        );
    }
}
