//! `--trace FILE.json`: the run as Chrome trace events (Perfetto, chrome://tracing).
//! One track per clock; on it a slice for the run, one per frame at the frame's
//! start, and one per pass at frame start + the pass's start offset, so passes
//! nest in their frame and frames in the run. Where the frames carry their
//! start on the host's clock (calibrated GPU timestamps, or host fences), the
//! frames go there and a second track holds the CPU's record, submit and wait
//! spans: one timeline. Work counters (`--counters`) are
//! in each pass's arguments and on counter tracks (fragment and compute
//! invocations: the pass's count from its start, 0 from its end).

use super::run::RunReport;
use serde_json::{json, Value};

const PID: u32 = 1;
/// The CPU track's thread id (the queue's tracks count from 1).
const CPU_TID: u32 = 100;
/// The counter tracks' names.
const FRAGMENTS: &str = "fragment invocations";
const INVOCATIONS: &str = "compute invocations";

/// `ts` and `dur` in µs of a slice from `begin` to `end` ns, both rounded to whole
/// ns first: a pass that ends with its frame keeps ending with it (no nesting
/// broken by float sums), and readers that convert back to ns land on integers.
fn ts_dur(begin_ns: f64, end_ns: f64) -> (f64, f64) {
    let (b, e) = (begin_ns.round(), end_ns.round());
    (b / 1e3, (e.max(b) - b) / 1e3)
}

/// The trace as a JSON value (`{"traceEvents": [...], "displayTimeUnit": "ns"}`).
pub fn trace(report: &RunReport) -> Value {
    let mut clocks: Vec<&str> = Vec::new();
    for f in &report.per_frame {
        if !clocks.contains(&f.clock.as_str()) {
            clocks.push(&f.clock);
        }
    }
    let tid = |clock: &str| clocks.iter().position(|c| *c == clock).unwrap_or(0) + 1;
    let mut events = vec![json!({
        "name": "process_name", "ph": "M", "pid": PID, "tid": 0,
        "args": { "name": format!("dermis {} ({}) on {}", report.dermis_version, report.git_commit, report.fingerprint.device) },
    })];
    let aligned = report.per_frame.iter().any(|f| f.host_start_ns.is_some());
    if aligned {
        events.push(json!({
            "name": "thread_name", "ph": "M", "pid": PID, "tid": CPU_TID,
            "args": { "name": "CPU: record, submit, wait (host clock)" },
        }));
    }
    for c in &clocks {
        let name = match *c {
            "gpu-timestamp" if aligned => {
                "queue 0: GPU timestamps on the host clock (calibrated)".to_string()
            }
            "gpu-timestamp" => "queue 0: GPU timestamps".to_string(),
            "host-fence" => "queue 0: host clock, submit to fence per pass".to_string(),
            other => format!("queue 0: {other}"),
        };
        events.push(json!({
            "name": "thread_name", "ph": "M", "pid": PID, "tid": tid(c),
            "args": { "name": name },
        }));
    }
    // Frames without a start (no timestamps) follow the previous one.
    let mut slices = Vec::new();
    let mut counters = Vec::new();
    let mut cursor = 0.0f64;
    let mut run_end = 0.0f64;
    // Each run's clock starts again at 0: runs follow one another.
    let mut run_base = 0.0f64;
    for (i, f) in report.per_frame.iter().enumerate() {
        if i > 0 && f.run != report.per_frame[i - 1].run {
            run_base = run_end;
        }
        let start = match f.host_start_ns.filter(|_| aligned) {
            Some(h) => run_base + h,
            None => f.start_ns.map_or(cursor, |s| run_base + s),
        };
        for c in f.cpu_spans.iter().filter(|_| aligned) {
            let (ts, dur) = ts_dur(run_base + c.start_ns, run_base + c.start_ns + c.dur_ns);
            run_end = run_end.max(run_base + c.start_ns + c.dur_ns);
            let name = match &c.pass {
                Some(p) => format!("{} {p}", c.what),
                None => c.what.clone(),
            };
            slices.push(json!({
                "name": name, "cat": "cpu", "ph": "X", "pid": PID, "tid": CPU_TID,
                "ts": ts, "dur": dur, "args": { "run": f.run, "frame": f.frame },
            }));
        }
        let pass_end = f
            .passes
            .iter()
            .filter_map(|p| Some(p.start_ns? + p.gpu_ns?))
            .fold(0.0, f64::max);
        let span = f.gpu_frame_ns.unwrap_or(pass_end);
        cursor = start + span;
        run_end = run_end.max(cursor);
        let (ts, dur) = ts_dur(start, start + span);
        slices.push(json!({
            "name": format!("run {} frame {}", f.run, f.frame), "cat": "frame", "ph": "X",
            "pid": PID, "tid": tid(&f.clock), "ts": ts, "dur": dur,
            "args": {
                "run": f.run, "frame": f.frame, "warmup": f.warmup,
                "cpu_record_ns": f.cpu_record_ns, "cpu_submit_ns": f.cpu_submit_ns,
            },
        }));
        for p in &f.passes {
            let (Some(offset), Some(dur)) = (p.start_ns, p.gpu_ns) else {
                continue;
            };
            let (ts, dur_us) = ts_dur(start + offset, start + offset + dur);
            let mut args = json!({ "run": f.run, "frame": f.frame, "start_in_frame_ns": offset, "duration_ns": dur });
            if let Some(c) = &p.counters {
                args["counters"] = json!(c);
                for (name, value) in [
                    (FRAGMENTS, c.fragment_invocations),
                    (INVOCATIONS, c.compute_invocations),
                ] {
                    for (t, v) in [(ts, value), (ts + dur_us, 0)] {
                        counters.push(json!({
                            "name": name, "cat": "counter", "ph": "C", "pid": PID, "ts": t,
                            "args": { name: v },
                        }));
                    }
                }
            }
            slices.push(json!({
                "name": p.name, "cat": "pass", "ph": "X",
                "pid": PID, "tid": tid(&f.clock), "ts": ts, "dur": dur_us,
                "args": args,
            }));
        }
    }
    if let Some(first) = report.per_frame.first() {
        let s = &report.setup;
        events.push(json!({
            "name": "run", "cat": "run", "ph": "X", "pid": PID, "tid": tid(&first.clock),
            "ts": 0.0, "dur": ts_dur(0.0, run_end).1,
            "args": {
                "dermis_version": report.dermis_version, "git_commit": report.git_commit,
                "fingerprint": report.fingerprint, "run_id": report.run_id,
                "scene": s.scene, "mesh": s.mesh, "environment": s.environment,
                "irradiance_resolution": s.irradiance_resolution, "kernel": s.kernel,
                "chain": s.chain, "view": s.view, "occlusion": s.occlusion,
                "width": report.width, "height": report.height, "frames": report.frames,
                "runs": report.runs,
            },
        }));
    }
    events.extend(slices);
    events.extend(counters);
    json!({ "traceEvents": events, "displayTimeUnit": "ns" })
}

#[cfg(test)]
mod tests {
    use super::super::run::tests::report;
    use super::*;

    fn slices<'a>(t: &'a Value, cat: &str) -> Vec<&'a Value> {
        t["traceEvents"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|e| e["cat"] == cat)
            .collect()
    }

    const EPS: f64 = 1e-9;

    fn span(e: &Value) -> (f64, f64) {
        let ts = e["ts"].as_f64().unwrap();
        (ts, ts + e["dur"].as_f64().unwrap())
    }

    #[test]
    fn passes_nest_in_their_frame_without_overlap() {
        let text = serde_json::to_string(&trace(&report(&[30.0, 10.0, 20.0]))).unwrap();
        let t: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(t["displayTimeUnit"], "ns");
        let frames = slices(&t, "frame");
        let passes = slices(&t, "pass");
        assert_eq!((frames.len(), passes.len()), (3, 6));
        for e in frames.iter().chain(&passes) {
            assert_eq!(e["ph"], "X");
            assert_eq!(e["pid"], 1);
            assert_eq!(e["tid"], 1);
        }
        for f in &frames {
            let (f0, f1) = span(f);
            let mut mine: Vec<(f64, f64)> = passes
                .iter()
                .filter(|p| p["args"]["frame"] == f["args"]["frame"])
                .map(|p| span(p))
                .collect();
            assert_eq!(mine.len(), 2);
            mine.sort_by(|a, b| a.0.total_cmp(&b.0));
            // µs floats: allow rounding at the 1e-9 µs level.
            for (p0, p1) in &mine {
                assert!(
                    f0 <= *p0 && *p1 <= f1 + EPS,
                    "{p0}..{p1} outside {f0}..{f1}"
                );
            }
            assert!(mine[0].1 <= mine[1].0 + EPS, "passes overlap: {mine:?}");
        }
        // Frame 1 starts at 1000 ns = 1 µs, lasts 30 ns; its pass "a" at +10 ns.
        let (f0, f1) = span(frames[1]);
        assert!(f0 == 1.0 && (f1 - 1.03).abs() < EPS, "{f0}..{f1}");
        assert_eq!(passes[2]["name"], "a");
        assert_eq!(span(passes[2]).0, 1.01);
        let run = slices(&t, "run");
        assert_eq!(run[0]["args"]["irradiance_resolution"], 256);
        assert_eq!(span(run[0]), (0.0, 2.04));
        let names: Vec<_> = t["traceEvents"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|e| e["ph"] == "M")
            .map(|e| e["name"].as_str().unwrap())
            .collect();
        assert_eq!(names, ["process_name", "thread_name"]);
    }

    #[test]
    fn fractional_ns_keep_a_pass_that_ends_with_its_frame_inside_it() {
        // Timestamp periods make fractional ns; the last pass ends with the frame.
        let mut r = report(&[30.0]);
        let f = &mut r.per_frame[0];
        f.start_ns = Some(1000.6);
        f.gpu_frame_ns = Some(10.3);
        f.passes[1].start_ns = Some(5.1);
        f.passes[1].gpu_ns = Some(5.2);
        f.passes.truncate(2);
        let t = trace(&r);
        let (frame, pass) = (slices(&t, "frame")[0], slices(&t, "pass")[1]);
        // Whole ns: frame 1001..1011, pass 1006..1011.
        assert_eq!(
            (frame["ts"].as_f64(), frame["dur"].as_f64()),
            (Some(1.001), Some(0.01))
        );
        assert_eq!(
            (pass["ts"].as_f64(), pass["dur"].as_f64()),
            (Some(1.006), Some(0.005))
        );
    }

    #[test]
    fn counters_are_pass_arguments_and_counter_tracks() {
        let mut r = report(&[30.0]);
        r.per_frame[0].passes[0].counters = Some(crate::timing::PassCounters {
            fragment_invocations: 96,
            compute_invocations: 7,
            ..Default::default()
        });
        let t = trace(&r);
        let pass = slices(&t, "pass")[0];
        assert_eq!(pass["args"]["counters"]["fragment_invocations"], 96);
        assert!(slices(&t, "pass")[1]["args"].get("counters").is_none());
        let c = slices(&t, "counter");
        assert_eq!(c.len(), 4);
        // The fragments' track: 96 from the pass's start, 0 from its end.
        let (p0, p1) = span(pass);
        assert_eq!(c[0]["ph"], "C");
        assert_eq!(c[0]["name"], FRAGMENTS);
        assert_eq!(
            (c[0]["ts"].as_f64().unwrap(), &c[0]["args"][FRAGMENTS]),
            (p0, &json!(96))
        );
        assert_eq!(
            (c[1]["ts"].as_f64().unwrap(), &c[1]["args"][FRAGMENTS]),
            (p1, &json!(0))
        );
        assert_eq!(c[2]["args"][INVOCATIONS], 7);
    }

    #[test]
    fn host_clock_frames_and_cpu_spans_share_the_timeline() {
        let mut r = report(&[30.0]);
        let f = &mut r.per_frame[0];
        // GPU timestamps say 1000; calibrated, the frame began at 5000 on the host.
        f.start_ns = Some(1000.0);
        f.host_start_ns = Some(5000.0);
        f.cpu_spans = vec![
            crate::timing::CpuSpan {
                what: "record".into(),
                start_ns: 4000.0,
                dur_ns: 500.0,
                ..Default::default()
            },
            crate::timing::CpuSpan {
                what: "wait".into(),
                start_ns: 4600.0,
                dur_ns: 500.0,
                ..Default::default()
            },
        ];
        let t = trace(&r);
        assert_eq!(span(slices(&t, "frame")[0]).0, 5.0);
        let cpu = slices(&t, "cpu");
        assert_eq!(cpu.len(), 2);
        assert!(cpu.iter().all(|e| e["tid"] == CPU_TID));
        assert_eq!(
            (cpu[1]["name"].as_str(), span(cpu[1])),
            (Some("wait"), (4.6, 5.1))
        );
        let names: Vec<_> = t["traceEvents"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|e| e["ph"] == "M")
            .map(|e| e["args"]["name"].as_str().unwrap().to_string())
            .collect();
        assert!(names.iter().any(|n| n.starts_with("CPU")), "{names:?}");
    }

    #[test]
    fn frames_without_a_start_follow_each_other() {
        let mut r = report(&[30.0, 10.0]);
        for f in &mut r.per_frame {
            f.start_ns = None;
        }
        let t = trace(&r);
        let frames = slices(&t, "frame");
        assert_eq!(span(frames[0]), (0.0, 0.05));
        assert_eq!(span(frames[1]).0, 0.05);
    }
}
