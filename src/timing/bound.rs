//! What bounds a pass (docs/design/pass-analysis.md): memory, shading, the fixed-
//! function units or per-pass overhead, from what a report measured — its
//! time against an empty dispatch's, its nominal bandwidth against the copy
//! ruler's, and its work counters — in the roofline's spirit (Williams,
//! Waterman & Patterson 2009): a pass that moves its bytes near the speed of a
//! plain copy is memory-bound; one far below it does work of its own.

use super::PassCounters;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A pass within this many times an empty dispatch's time is overhead: the
/// time to start, drain and time a pass is most of it.
pub const OVERHEAD_X_EMPTY: f64 = 2.0;
/// A pass whose nominal traffic reaches this share of the copy ruler's
/// bandwidth is memory-bound: half of what a plain copy achieves.
pub const MEMORY_OF_RULER: f64 = 0.5;
/// A draw whose triangles shade fewer fragments than this each is bound by
/// triangle setup and rasterisation: GPUs shade 2 × 2 quads and rasterise in
/// tiles, and below about 10 pixels a triangle's quads are mostly partial
/// (Fatahalian et al. 2010, "Reducing shading on GPUs using quad-fragment
/// merging", Fig. 2: ≥ 2× over-shading at 10-pixel triangles).
pub const FRAGMENTS_PER_TRIANGLE: f64 = 10.0;
/// A pass that, with its shader's work skipped (one read and its output
/// kept: `render --variants`), takes at most this share of its time is bound
/// by that work; above it, by what the variant keeps: the output and, for a
/// draw, rasterisation and the depth test.
pub const SKIPPED_SHARE: f64 = 0.5;

/// The tag of a pass whose pipeline was made with its work skipped
/// (gpu::Context::set_skip_work).
pub const WORK_SKIPPED_TAG: &str = "work-skipped";
/// The tag a work-skipped pass that draws carries beside it.
pub const DRAW_TAG: &str = "draw";

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Bound {
    /// Start, drain and timing of the pass: its size hardly matters.
    Overhead,
    /// Moving its bytes: near the copy ruler's bandwidth.
    Memory,
    /// Triangle setup and rasterisation: many small triangles.
    FixedFunction,
    /// Its shaders' own work (arithmetic, texture filtering, latency).
    Shading,
}

impl Bound {
    pub fn name(self) -> &'static str {
        match self {
            Bound::Overhead => "overhead",
            Bound::Memory => "memory",
            Bound::FixedFunction => "fixed-function",
            Bound::Shading => "shading",
        }
    }
}

/// The verdict with the figure that decided it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct BoundBy {
    pub bound: Bound,
    pub why: String,
}

/// What a pass's verdict is made from.
#[derive(Clone, Copy, Debug, Default)]
pub struct PassFigures {
    pub median_ns: f64,
    /// An empty dispatch's median in the same run (`ruler_empty`).
    pub empty_ns: Option<f64>,
    /// Nominal bandwidth over the copy ruler's.
    pub of_ruler_bandwidth: Option<f64>,
    pub counters: Option<PassCounters>,
    /// Its median with its shader's work skipped over its median
    /// (`render --variants`); `None` where not measured.
    pub work_skipped_share: Option<f64>,
    /// It draws (else it dispatches), where the variant said.
    pub draw: bool,
}

/// The first rule that holds, in this order: overhead (within
/// [`OVERHEAD_X_EMPTY`] of an empty dispatch), memory (≥ [`MEMORY_OF_RULER`]
/// of the copy's bandwidth), the work-skipped variant where it ran (shading
/// at most [`SKIPPED_SHARE`] of the time left, else fixed function for a
/// draw and memory for a dispatch), fixed function (a draw of fewer than
/// [`FRAGMENTS_PER_TRIANGLE`] fragments per triangle after clipping), else
/// shading. `None` without the empty dispatch or the ruler to judge by.
pub fn bound_by(f: &PassFigures) -> Option<BoundBy> {
    let empty = f.empty_ns.filter(|&e| e > 0.0)?;
    let x_empty = f.median_ns / empty;
    if x_empty <= OVERHEAD_X_EMPTY {
        return Some(BoundBy {
            bound: Bound::Overhead,
            why: format!("{x_empty:.1}× an empty dispatch's time"),
        });
    }
    let bw = f.of_ruler_bandwidth?;
    if bw >= MEMORY_OF_RULER {
        return Some(BoundBy {
            bound: Bound::Memory,
            why: format!("{:.0} % of the copy ruler's bandwidth", 100.0 * bw),
        });
    }
    if let Some(share) = f.work_skipped_share {
        let kept = format!(
            "with its work skipped it takes {:.0} % of its time",
            100.0 * share
        );
        let (bound, why) = if share <= SKIPPED_SHARE {
            (Bound::Shading, kept)
        } else if f.draw {
            (
                Bound::FixedFunction,
                format!("{kept}: rasterisation, depth test, output"),
            )
        } else {
            (Bound::Memory, format!("{kept}: one read and the output"))
        };
        return Some(BoundBy { bound, why });
    }
    if let Some(c) = f.counters.filter(|c| c.clipping_primitives > 0) {
        let per = c.fragment_invocations as f64 / c.clipping_primitives as f64;
        if per < FRAGMENTS_PER_TRIANGLE {
            return Some(BoundBy {
                bound: Bound::FixedFunction,
                why: format!(
                    "{per:.1} fragments per triangle ({} triangles)",
                    c.clipping_primitives
                ),
            });
        }
    }
    Some(BoundBy {
        bound: Bound::Shading,
        why: format!(
            "{:.0} % of the copy ruler's bandwidth, {x_empty:.0}× an empty dispatch",
            100.0 * bw
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figures(median_ns: f64, bw: f64) -> PassFigures {
        PassFigures {
            median_ns,
            empty_ns: Some(1000.0),
            of_ruler_bandwidth: Some(bw),
            counters: None,
            work_skipped_share: None,
            draw: false,
        }
    }

    #[test]
    fn rules_in_order() {
        let b = |f: &PassFigures| bound_by(f).unwrap().bound;
        // Within 2× an empty dispatch: overhead, whatever its bandwidth.
        assert_eq!(b(&figures(1900.0, 0.9)), Bound::Overhead);
        assert_eq!(b(&figures(1e6, 0.9)), Bound::Memory);
        assert_eq!(b(&figures(1e6, 0.1)), Bound::Shading);
        // A draw of 1000 triangles shading 5000 fragments: 5 per triangle.
        let mut small = figures(1e6, 0.1);
        small.counters = Some(PassCounters {
            clipping_primitives: 1000,
            fragment_invocations: 5000,
            ..Default::default()
        });
        let v = bound_by(&small).unwrap();
        assert_eq!(v.bound, Bound::FixedFunction);
        assert!(v.why.contains("5.0 fragments per triangle"), "{}", v.why);
        // 2 triangles over 100 000 pixels: shading.
        small.counters = Some(PassCounters {
            clipping_primitives: 2,
            fragment_invocations: 100_000,
            ..Default::default()
        });
        assert_eq!(b(&small), Bound::Shading);
        // The work-skipped variant, after the bandwidth and before the counters.
        let mut skipped = figures(1e6, 0.1);
        skipped.work_skipped_share = Some(0.2);
        assert_eq!(b(&skipped), Bound::Shading);
        skipped.work_skipped_share = Some(0.8);
        assert_eq!(b(&skipped), Bound::Memory);
        skipped.draw = true;
        let v = bound_by(&skipped).unwrap();
        assert_eq!(v.bound, Bound::FixedFunction);
        assert!(v.why.contains("80 % of its time"), "{}", v.why);
        skipped.of_ruler_bandwidth = Some(0.9);
        assert_eq!(b(&skipped), Bound::Memory);
        // Nothing to judge by.
        let mut none = figures(1e6, 0.1);
        none.empty_ns = None;
        assert!(bound_by(&none).is_none());
        none.empty_ns = Some(1000.0);
        none.of_ruler_bandwidth = None;
        assert!(bound_by(&none).is_none());
    }
}
