//! Timing reports: per frame, each pass's GPU time and start within the frame
//! and the CPU record/submit time; run reports with statistics over warmed-up
//! frames; trace and CSV output.

#[cfg(test)]
mod aa_study;
mod bootstrap;
mod bound;
mod counters;
pub mod csv;
pub mod export;
pub mod fingerprint;
mod measurement;
pub mod regression;
mod run;
mod significance;
mod stats;
pub mod trace;
mod ttest;
mod verdict;

pub use bound::{Bound, BoundBy, DRAW_TAG, WORK_SKIPPED_TAG};
pub use counters::PassCounters;
pub use fingerprint::Fingerprint;
pub use run::{
    is_ruler, CameraSetup, MemoryUse, PassStats, PipelineTime, RunReport, RunSetup, GIT_COMMIT,
    GIT_DIRTY, RULER_COPY, RULER_EMPTY, RULER_READ, SCHEMA_VERSION, VERSION,
};
pub use stats::Stats;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// What a pass is measured against: the texels (invocations, or pixels of its
/// render area) it computes and its nominal memory traffic, every graph image and
/// buffer it reads or writes counted once at full size; and its tags (what it
/// belongs to, e.g. the diffusion chain).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct PassWork {
    pub texels: Option<u64>,
    pub bytes: u64,
    /// `bytes` with each image capped at one texel per invocation: what a pass
    /// that samples a large image at few points can touch of it.
    pub touched_bytes: u64,
    pub tags: Vec<&'static str>,
}

/// GPU time of one pass of one frame.
#[derive(Clone, Debug, Default, Serialize, Deserialize, JsonSchema)]
pub struct PassTime {
    pub name: String,
    /// `None`: the pass said nothing about its size.
    pub texels: Option<u64>,
    /// Nominal traffic (see [`PassWork`]).
    pub bytes: Option<u64>,
    /// Traffic it can touch (see [`PassWork`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub touched_bytes: Option<u64>,
    /// What the pass belongs to (e.g. `diffusion`, `ruler`), as it declared.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub tags: Vec<String>,
    /// `None` when the device has no timestamps or the delta was not positive.
    pub gpu_ns: Option<f64>,
    /// From the frame's start (first timestamp, or host start with host fences)
    /// to the pass's start.
    pub start_ns: Option<f64>,
    /// Pipeline statistics (`render --counters`); absent when not counted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub counters: Option<PassCounters>,
}

/// A span of the CPU's work for a frame, on the host's clock.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct CpuSpan {
    /// `record`, `submit` or `wait` (for the frame's fence).
    pub what: String,
    /// The pass it was for, where one submission per pass (host fences).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pass: Option<String>,
    /// From the executor's first frame's host start.
    pub start_ns: f64,
    pub dur_ns: f64,
}

/// What one frame cost.
#[derive(Clone, Debug, Default, Serialize, Deserialize, JsonSchema)]
pub struct FrameTiming {
    /// The repetition (`render --runs`) it belongs to, from 0.
    #[serde(default)]
    pub run: u32,
    /// Within its run, from 0.
    pub frame: u64,
    /// A warm-up frame, outside the statistics.
    #[serde(default)]
    pub warmup: bool,
    /// The frame's start after the executor's first frame's, on the same clock.
    pub start_ns: Option<f64>,
    pub passes: Vec<PassTime>,
    /// From a timestamp before the first pass to one after the last.
    pub gpu_frame_ns: Option<f64>,
    pub cpu_record_ns: f64,
    pub cpu_submit_ns: f64,
    /// Deltas that came out zero or negative and were dropped.
    pub dropped_deltas: u32,
    /// What measured the passes: "gpu-timestamp" or "host-fence".
    pub clock: String,
    /// The frame's start on the host's clock, from the executor's first
    /// frame's host start — the clock of `cpu_spans`: GPU timestamps put on
    /// it by calibrated timestamps, or the host clock itself with host fences.
    /// `None` where the clocks are not aligned.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub host_start_ns: Option<f64>,
    /// The CPU's record, submit and wait spans for this frame.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cpu_spans: Vec<CpuSpan>,
}

impl FrameTiming {
    /// Sum of the passes' GPU times (≤ `gpu_frame_ns`: barriers and gaps are outside).
    pub fn gpu_pass_sum_ns(&self) -> f64 {
        self.passes.iter().filter_map(|p| p.gpu_ns).sum()
    }

    /// Attaches each pass's work, in pass order.
    pub fn set_work(&mut self, work: &[PassWork]) {
        for (p, w) in self.passes.iter_mut().zip(work) {
            p.texels = w.texels;
            p.bytes = Some(w.bytes);
            p.touched_bytes = Some(w.touched_bytes);
            p.tags = w.tags.iter().map(|t| t.to_string()).collect();
        }
    }

    pub fn pass(&self, name: &str) -> Option<&PassTime> {
        self.passes.iter().find(|p| p.name == name)
    }

    pub fn pass_ns(&self, name: &str) -> Option<f64> {
        self.passes.iter().find(|p| p.name == name)?.gpu_ns
    }

    /// Turns raw 64-bit timestamps (frame begin, frame end, then begin/end per pass)
    /// into durations and starts within the frame: masked to `valid_bits`, scaled
    /// by `period_ns`.
    pub fn from_timestamps(
        frame: u64,
        names: &[String],
        raw: &[u64],
        valid_bits: u32,
        period_ns: f32,
    ) -> Self {
        let mask = if valid_bits >= 64 {
            u64::MAX
        } else {
            (1u64 << valid_bits) - 1
        };
        let mut dropped = 0;
        let mut delta = |a: Option<&u64>, b: Option<&u64>| -> Option<f64> {
            let (a, b) = (a? & mask, b? & mask);
            if b <= a {
                dropped += 1;
                return None;
            }
            Some((b - a) as f64 * period_ns as f64)
        };
        let gpu_frame_ns = delta(raw.first(), raw.get(1));
        // A pass may start on the frame's first tick: offsets of 0 are kept.
        let offset = |b: Option<&u64>| -> Option<f64> {
            let (a, b) = (raw.first()? & mask, b? & mask);
            (b >= a).then(|| (b - a) as f64 * period_ns as f64)
        };
        let passes = names
            .iter()
            .enumerate()
            .map(|(i, name)| PassTime {
                name: name.clone(),
                gpu_ns: delta(raw.get(2 + 2 * i), raw.get(3 + 2 * i)),
                start_ns: offset(raw.get(2 + 2 * i)),
                ..Default::default()
            })
            .collect();
        FrameTiming {
            frame,
            passes,
            gpu_frame_ns,
            dropped_deltas: dropped,
            clock: "gpu-timestamp".into(),
            ..Default::default()
        }
    }

    /// Attaches each pass's counters, in pass order.
    pub fn set_counters(&mut self, counters: &[PassCounters]) {
        for (p, c) in self.passes.iter_mut().zip(counters) {
            p.counters = Some(*c);
        }
    }

    pub fn pass_start_ns(&self, name: &str) -> Option<f64> {
        self.passes.iter().find(|p| p.name == name)?.start_ns
    }

    /// Per-pass medians (times and starts) over several frames (same pass list),
    /// e.g. after warm-up.
    pub fn median(frames: &[FrameTiming]) -> Option<FrameTiming> {
        let last = frames.last()?;
        let med = |v: Vec<f64>| stats::median(&v);
        let passes = last
            .passes
            .iter()
            .map(|p| PassTime {
                name: p.name.clone(),
                texels: p.texels,
                bytes: p.bytes,
                touched_bytes: p.touched_bytes,
                tags: p.tags.clone(),
                gpu_ns: med(frames.iter().filter_map(|f| f.pass_ns(&p.name)).collect()),
                start_ns: med(frames
                    .iter()
                    .filter_map(|f| f.pass_start_ns(&p.name))
                    .collect()),
                counters: PassCounters::median(
                    &frames
                        .iter()
                        .filter_map(|f| f.pass(&p.name)?.counters)
                        .collect::<Vec<_>>(),
                ),
            })
            .collect();
        Some(FrameTiming {
            frame: last.frame,
            start_ns: None,
            passes,
            gpu_frame_ns: med(frames.iter().filter_map(|f| f.gpu_frame_ns).collect()),
            cpu_record_ns: med(frames.iter().map(|f| f.cpu_record_ns).collect()).unwrap_or(0.0),
            cpu_submit_ns: med(frames.iter().map(|f| f.cpu_submit_ns).collect()).unwrap_or(0.0),
            dropped_deltas: frames.iter().map(|f| f.dropped_deltas).sum(),
            clock: last.clock.clone(),
            ..Default::default()
        })
    }

    /// A fixed-width table for terminals.
    pub fn table(&self) -> String {
        let ms = |ns: Option<f64>| ns.map_or("n/a".to_string(), |v| format!("{:.3}", v / 1e6));
        let mut s = format!(
            "{:<24} {:>12}   (clock: {})\n",
            "pass", "GPU ms", self.clock
        );
        for p in &self.passes {
            s += &format!("{:<24} {:>12}\n", p.name, ms(p.gpu_ns));
        }
        s += &format!(
            "{:<24} {:>12}\n",
            "sum of passes",
            ms(Some(self.gpu_pass_sum_ns()))
        );
        s += &format!("{:<24} {:>12}\n", "frame (GPU span)", ms(self.gpu_frame_ns));
        s += &format!(
            "{:<24} {:>12}\n",
            "CPU record",
            ms(Some(self.cpu_record_ns))
        );
        s += &format!(
            "{:<24} {:>12}\n",
            "CPU submit",
            ms(Some(self.cpu_submit_ns))
        );
        if self.dropped_deltas > 0 {
            s += &format!(
                "({} non-positive timestamp deltas dropped)\n",
                self.dropped_deltas
            );
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timestamps_are_masked_scaled_and_bad_deltas_dropped() {
        let names = vec!["a".to_string(), "b".to_string()];
        // 36 valid bits: the high garbage bit must be masked away.
        let hi = 1u64 << 40;
        let raw = [hi | 100, hi | 1100, 200, 600, 700, 700];
        let r = FrameTiming::from_timestamps(3, &names, &raw, 36, 2.0);
        assert_eq!(r.gpu_frame_ns, Some(2000.0));
        assert_eq!(r.pass_ns("a"), Some(800.0));
        assert_eq!(r.pass_ns("b"), None);
        assert_eq!(r.dropped_deltas, 1);
        // Starts from the (masked) frame begin: (200 - 100) × 2, (700 - 100) × 2.
        assert_eq!(r.pass_start_ns("a"), Some(200.0));
        assert_eq!(r.pass_start_ns("b"), Some(1200.0));
    }

    #[test]
    fn a_pass_before_the_frame_begin_has_no_start() {
        let names = vec!["a".to_string()];
        let r = FrameTiming::from_timestamps(0, &names, &[500, 900, 500, 600], 64, 1.0);
        assert_eq!(r.pass_start_ns("a"), Some(0.0));
        let r = FrameTiming::from_timestamps(0, &names, &[500, 900, 400, 600], 64, 1.0);
        assert_eq!(r.pass_start_ns("a"), None);
        assert_eq!(r.pass_ns("a"), Some(200.0));
    }

    #[test]
    fn median_per_pass() {
        let f = |v: f64| FrameTiming {
            passes: vec![PassTime {
                name: "p".into(),
                gpu_ns: Some(v),
                start_ns: Some(v + 1.0),
                ..Default::default()
            }],
            gpu_frame_ns: Some(v * 2.0),
            ..Default::default()
        };
        let m = FrameTiming::median(&[f(5.0), f(1.0), f(3.0), f(100.0)]).unwrap();
        assert_eq!(m.pass_ns("p"), Some(4.0));
        assert_eq!(m.pass_start_ns("p"), Some(5.0));
        assert_eq!(m.gpu_frame_ns, Some(8.0));
    }
}
