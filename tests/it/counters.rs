//! Work counters (pipeline statistics per pass): a compute pass of known size
//! counts exactly its dispatch's invocations, a full-screen draw shades at
//! least every pixel, with both clocks; without counters nothing is counted.

use crate::common;

use dermis::gpu::ImageDesc;
use dermis::graph::{Clock, Executor, Graph, LoadOp};
use dermis::testscene::{CompositePush, TestScene, HALF};
use dermis::timing::FrameTiming;

/// Not a multiple of pattern.comp's 8 × 8 workgroup: the last groups overhang.
const W: u32 = 100;
const H: u32 = 60;

/// Frames of: the test pattern (compute, W × H threads), then a full-screen
/// triangle compositing it into a W × H attachment.
fn frames(clock: Clock, counters: bool) -> Vec<FrameTiming> {
    common::with_gpu(|ctx| {
        let scene = TestScene::new(ctx).unwrap();
        let mut ex = Executor::new(ctx, 2).unwrap();
        ex.set_clock(clock).unwrap();
        ex.set_counters(counters).unwrap();
        let mut reports = Vec::new();
        for _ in 0..3 {
            let mut g = Graph::new();
            let mut pattern = g.create_image("pattern", ImageDesc::new(W, H, HALF));
            g.simple_pass("pattern", &scene.pattern)
                .store(&mut pattern)
                .constants(&[W, H])
                .dispatch([W, H, 1]);
            let mut out = g.create_image("out", ImageDesc::new(W, H, HALF));
            let push = CompositePush {
                scale: 1.0,
                bias: 0.0,
                split_x: f32::MAX,
                encode_srgb: 0,
            };
            scene.composite(&mut g, &pattern, &mut out, LoadOp::DontCare, push);
            g.output(&out);
            reports.extend(ex.run(g).unwrap());
        }
        reports.extend(ex.finish().unwrap());
        reports
    })
}

fn check(reports: &[FrameTiming]) {
    assert_eq!(reports.len(), 3);
    // 8 × 8 workgroups (pattern.comp's local size): ⌈100/8⌉ × ⌈60/8⌉ = 13 × 8
    // groups of 64 invocations.
    let groups = W.div_ceil(8) as u64 * H.div_ceil(8) as u64;
    for r in reports {
        let pattern = r.pass("pattern").unwrap();
        let c = pattern.counters.expect("the compute pass was counted");
        assert_eq!(c.compute_invocations, groups * 64, "{c:?}");
        assert_eq!(c.fragment_invocations, 0, "{c:?}");
        assert_eq!(c.input_vertices, 0, "{c:?}");
        let composite = r.pass("composite").unwrap();
        let c = composite.counters.expect("the draw was counted");
        // One triangle of three vertices covering the target.
        assert_eq!((c.input_vertices, c.input_primitives), (3, 1), "{c:?}");
        assert!(c.vertex_invocations >= 3, "{c:?}");
        assert_eq!(c.clipping_invocations, 1, "{c:?}");
        assert!(c.clipping_primitives >= 1, "{c:?}");
        assert!(c.fragment_invocations >= (W * H) as u64, "{c:?}");
        assert_eq!(c.compute_invocations, 0, "{c:?}");
    }
}

#[test]
fn host_fence_clock_counts_each_pass() {
    check(&frames(Clock::HostFence, true));
}

#[test]
fn gpu_timestamp_clock_counts_each_pass() {
    check(&frames(Clock::GpuTimestamp, true));
}

#[test]
fn without_counters_nothing_is_counted() {
    for clock in [Clock::HostFence, Clock::GpuTimestamp] {
        let reports = frames(clock, false);
        assert!(reports
            .iter()
            .flat_map(|r| &r.passes)
            .all(|p| p.counters.is_none()));
    }
}

/// A render's report: every pass of the default frame counted, the per-texel
/// figures derived, the table, and the fingerprint saying counters were on.
#[test]
fn every_pass_of_a_render_is_counted() {
    use dermis::render::{render_scene, RenderOptions};
    use dermis::scene::file::SceneFile;
    use dermis::scene::Scene;
    let mut file = SceneFile::default();
    file.render.irradiance_resolution = 256;
    (file.render.width, file.render.height) = (64, 48);
    let report = common::with_gpu(|ctx| {
        let scene = Scene::load(file).unwrap();
        let opts = RenderOptions {
            frames: 2,
            ruler: true,
            counters: true,
            ..RenderOptions::default()
        };
        render_scene(ctx, &scene, &opts).unwrap().report
    });
    assert!(report.fingerprint.counters);
    for p in &report.passes {
        let c = p
            .counters
            .unwrap_or_else(|| panic!("{} not counted", p.name));
        // Every pass of the frame draws or dispatches, except copies and readbacks.
        if c.compute_invocations > 0 {
            let per = p.invocations_per_texel.expect("texels declared");
            assert!(per >= 1.0, "{}: {per} invocations per texel", p.name);
        }
    }
    let copy = report
        .passes
        .iter()
        .find(|p| p.name == "ruler_copy")
        .unwrap();
    // The copy is one invocation per texel of 256² (its 8 × 8 groups fit).
    assert_eq!(copy.counters.unwrap().compute_invocations, 256 * 256);
    assert_eq!(copy.invocations_per_texel, Some(1.0));
    let skin = report.passes.iter().find(|p| p.name == "skin").unwrap();
    // Over-shading is the driver's (lavapipe shades occluded fragments before
    // its depth test): only that the pass shaded something.
    let f = skin.fragments_per_pixel.expect("the skin pass shades");
    assert!(f > 0.0, "skin: {f} fragments per pixel");
    // Creation feedback: the render's pipelines, each with a time, slowest first.
    assert!(!report.pipelines.is_empty());
    assert!(report.pipelines.iter().all(|p| p.creation_ns > 0.0));
    assert!(report
        .pipelines
        .windows(2)
        .all(|w| w[0].creation_ns >= w[1].creation_ns));
    let table = report.table();
    assert!(
        table.contains("frag/px") && table.contains("inv/texel"),
        "{table}"
    );
    assert!(table.contains("pipelines (once per render)"), "{table}");
}
