//! Per-pass timing: every pass of a frame gets a positive duration and a start,
//! and the passes fit inside the frame's span, with both clocks.

mod common;

use dermis::graph::upload::Readback;
use dermis::graph::{Clock, Executor, Graph};
use dermis::profile::FrameReport;
use dermis::testscene::TestScene;

fn frames(clock: Clock) -> Vec<FrameReport> {
    common::with_gpu(|ctx| {
        let (w, h) = (96, 64);
        let scene = TestScene::new(ctx).unwrap();
        let readback = Readback::new(ctx, "readback", w as u64 * h as u64 * 4).unwrap();
        let mut ex = Executor::new(ctx, 2).unwrap();
        ex.set_clock(clock).unwrap();
        let mut reports = Vec::new();
        for _ in 0..4 {
            let mut g = Graph::new();
            scene.frame(&mut g, w, h, &readback);
            reports.extend(ex.run(g).unwrap());
        }
        reports.extend(ex.finish().unwrap());
        reports
    })
}

fn check(reports: &[FrameReport], clock: &str) {
    assert_eq!(reports.len(), 4);
    for (i, r) in reports.iter().enumerate() {
        assert_eq!(r.frame, i as u64, "reports come back in frame order");
        assert_eq!(r.clock, clock);
        let names: Vec<_> = r.passes.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(
            names,
            ["pattern", "blur_h", "blur_v", "composite", "readback"]
        );
        for p in &r.passes {
            let ns = p
                .gpu_ns
                .unwrap_or_else(|| panic!("{} has no time: {r:?}", p.name));
            assert!(ns > 0.0, "{}: {ns}", p.name);
        }
        let span = r.gpu_frame_ns.expect("frame span");
        assert!(
            r.gpu_pass_sum_ns() <= span,
            "passes {} > frame {span}",
            r.gpu_pass_sum_ns()
        );
        assert_eq!(r.dropped_deltas, 0);
        // Passes start in order and end within the frame.
        let mut previous_end = 0.0;
        for p in &r.passes {
            let start = p
                .start_ns
                .unwrap_or_else(|| panic!("{} has no start", p.name));
            let end = start + p.gpu_ns.unwrap();
            assert!(
                start >= previous_end,
                "{} starts before the last ends: {r:?}",
                p.name
            );
            assert!(
                end <= span,
                "{} ends at {end}, after the frame ({span})",
                p.name
            );
            previous_end = end;
        }
    }
    // Frames are placed on one timeline from the first frame's start.
    let starts: Vec<f64> = reports.iter().map(|r| r.start_ns.unwrap()).collect();
    assert_eq!(starts[0], 0.0);
    assert!(starts.windows(2).all(|w| w[0] < w[1]), "{starts:?}");
    let json = serde_json::to_string(&reports[0]).unwrap();
    assert!(json.contains("\"blur_h\""));
}

#[test]
fn host_fence_clock() {
    check(&frames(Clock::HostFence), "host-fence");
}

#[test]
fn gpu_timestamp_clock() {
    check(&frames(Clock::GpuTimestamp), "gpu-timestamp");
}
