//! One timeline: GPU passes and the CPU's record, submit and wait spans on the
//! host's clock. A CPU span that waits on a frame's fence ends after that
//! frame's last GPU pass, with calibrated GPU timestamps and with host fences.

use crate::common;

use dermis::graph::upload::Readback;
use dermis::graph::{Clock, Executor, Graph};
use dermis::testscene::TestScene;
use dermis::timing::FrameTiming;

/// The frames, whether the device calibrates, and how far its GPU times on
/// the host clock may be off (ns; 0 on host fences).
fn frames(clock: Clock) -> (Vec<FrameTiming>, bool, f64) {
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
        let uncertainty = ex.calibration_uncertainty_ns().unwrap_or(0.0);
        reports.extend(ex.finish().unwrap());
        (reports, ctx.info.calibrated_timestamps, uncertainty)
    })
}

/// Every frame: on the host clock, its record span before its first pass, and
/// its last wait ending at or after its last pass's end — within `slack` ns,
/// the calibration's uncertainty (the driver's deviation and the length of the
/// calibrating call, which a loaded machine stretches).
fn check(reports: &[FrameTiming], slack: f64) {
    assert_eq!(reports.len(), 4);
    for r in reports {
        let start = r
            .host_start_ns
            .unwrap_or_else(|| panic!("frame {} is not on the host clock", r.frame));
        let last_end = r
            .passes
            .iter()
            .filter_map(|p| Some(start + p.start_ns? + p.gpu_ns?))
            .fold(f64::MIN, f64::max);
        assert!(last_end > start, "frame {}: no pass timed", r.frame);
        let wait = r
            .cpu_spans
            .iter()
            .rfind(|s| s.what == "wait")
            .unwrap_or_else(|| panic!("frame {}: no wait span", r.frame));
        let wait_end = wait.start_ns + wait.dur_ns;
        assert!(
            wait_end + slack >= last_end,
            "frame {}: the wait ended at {wait_end} ns, before its last pass ({last_end} ns)",
            r.frame
        );
        let record = r.cpu_spans.iter().find(|s| s.what == "record").unwrap();
        let first = start + r.passes[0].start_ns.unwrap();
        assert!(
            record.start_ns <= first + slack,
            "frame {}: recording began at {} ns, after its first pass ({first} ns, slack {slack} ns)",
            r.frame,
            record.start_ns
        );
    }
}

#[test]
fn calibrated_gpu_timestamps() {
    let (reports, calibrated, slack) = frames(Clock::GpuTimestamp);
    assert!(calibrated, "the device offers no calibrated timestamps");
    println!("calibration uncertainty {slack} ns");
    check(&reports, slack);
}

#[test]
fn host_fences() {
    check(&frames(Clock::HostFence).0, 0.0);
}
