//! Per-pass timing: every pass of a frame gets a positive duration and a start,
//! and the passes fit inside the frame's span, with both clocks.

use crate::common;

use dermis::graph::upload::Readback;
use dermis::graph::{Clock, Executor, Graph};
use dermis::testscene::TestScene;
use dermis::timing::FrameTiming;

fn frames(clock: Clock) -> Vec<FrameTiming> {
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

fn check(reports: &[FrameTiming], clock: &str) {
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

/// The rulers and every pass's work: texels from the dispatch or render area,
/// nominal bytes from the images it uses; ×ruler relative to `ruler_copy`.
#[test]
fn rulers_and_per_texel_figures() {
    use dermis::render::{render_scene, RenderOptions};
    use dermis::scene::file::{Chain, SceneFile};
    use dermis::scene::Scene;
    let (res, w, h) = (256u64, 64u32, 48u32);
    let mut file = SceneFile::default();
    file.render.irradiance_resolution = res as u32;
    (file.render.width, file.render.height) = (w, h);
    file.skin.chain = Chain::Full;
    let report = |ruler| {
        common::with_gpu(|ctx| {
            let scene = Scene::load(file.clone()).unwrap();
            let opts = RenderOptions {
                frames: 2,
                ruler,
                ..RenderOptions::default()
            };
            render_scene(ctx, &scene, &opts).unwrap().report
        })
    };
    let r = report(true);
    let pass = |name: &str| r.passes.iter().find(|p| p.name == name).unwrap();
    // The copy reads and writes one RGBA16F image of res²; the read only reads it
    // (and writes a 1×1 sink).
    assert_eq!(pass("ruler_copy").texels, Some(res * res));
    assert_eq!(pass("ruler_copy").bytes, Some(2 * res * res * 8));
    assert_eq!(pass("ruler_read").bytes, Some(res * res * 8 + 8));
    assert_eq!(pass("ruler_copy").x_ruler, Some(1.0));
    // A blur pass (level 1, narrow: one pass for both directions) reads the
    // level and the stretch map (≤ 1024², here res²) and writes one image.
    let blur = pass("blur1");
    assert_eq!(blur.texels, Some(res * res));
    assert_eq!(blur.bytes, Some(3 * res * res * 8));
    let ns = blur.time.unwrap().median_ns / (res * res) as f64;
    assert!((blur.ns_per_texel.unwrap() - ns).abs() < 1e-9 * ns.max(1.0));
    let copy = pass("ruler_copy").ns_per_texel.unwrap();
    assert!((blur.x_ruler.unwrap() - ns / copy).abs() < 1e-9 * (ns / copy));
    // Bandwidth over the copy's: bytes / median, over the copy's bytes / median.
    assert_eq!(pass("ruler_copy").of_ruler_bandwidth, Some(1.0));
    let copy_gb = (2 * res * res * 8) as f64 / pass("ruler_copy").time.unwrap().median_ns;
    let bw = (3 * res * res * 8) as f64 / blur.time.unwrap().median_ns / copy_gb;
    assert!((blur.of_ruler_bandwidth.unwrap() - bw).abs() < 1e-9 * bw);
    // The final pass samples the 256² levels at 64 × 48 pixels: it can touch
    // one texel of each per pixel, not the whole level.
    let skin = pass("skin");
    assert!(
        skin.touched_bytes.unwrap() < skin.bytes.unwrap(),
        "{skin:?}"
    );
    assert_eq!(blur.touched_bytes, blur.bytes);
    // Screen passes count output pixels.
    assert_eq!(pass("skin").texels, Some(w as u64 * h as u64));
    assert!(r.table().contains("ns/texel") && r.table().contains("×ruler"));
    // Without the rulers nothing is relative to them.
    let r = report(false);
    assert!(r.passes.iter().all(|p| !p.name.starts_with("ruler_")));
    assert!(r.passes.iter().all(|p| p.x_ruler.is_none()));
    assert!(r.passes.iter().all(|p| p.of_ruler_bandwidth.is_none()));
    assert!(r.passes.iter().any(|p| p.ns_per_texel.is_some()));
}
