//! The bound-by verdict on its known cases: the ruler copy is memory-bound, an
//! all-arithmetic pass is shading-bound, a 1-texel dispatch is overhead; and
//! the controlled variant with the work skipped (`render --variants`).

use crate::common;

use dermis::gpu::{ImageDesc, Pipelines, Sampler};
use dermis::graph::{Executor, Graph};
use dermis::testscene::{TestScene, HALF};
use dermis::timing::{Bound, MemoryUse, RunReport, RunSetup, WORK_SKIPPED_TAG};
use std::sync::Arc;

/// The known cases' frames (16, the first warm-up) through `scene`'s
/// pipelines: medians of 15 measured frames (with 5, a loaded machine's
/// preemptions reached the median: ruler_empty 2.4 ms, its minimum 0.13).
fn known_cases(ctx: &Arc<dermis::gpu::Context>) -> RunReport {
    let scene = TestScene::new(ctx).unwrap();
    let pipelines = Pipelines::new(ctx);
    let sampler = Arc::new(Sampler::clamped(ctx, false).unwrap());
    let mut ex = Executor::new(ctx, 2).unwrap();
    ex.set_counters(true).unwrap();
    let mut frames = Vec::new();
    for _ in 0..16 {
        let mut g = Graph::new();
        let n = 256;
        let mut src = g.create_image("pattern", ImageDesc::new(n, n, HALF));
        g.simple_pass("pattern", &scene.pattern)
            .store(&mut src)
            .constants(&[n, n])
            .dispatch([n, n, 1]);
        dermis::render::ruler::passes(&mut g, &pipelines, &sampler, &src).unwrap();
        let mut one = g.create_image("one", ImageDesc::new(1, 1, HALF));
        g.simple_pass("one_texel", &scene.pattern)
            .store(&mut one)
            .constants(&[1u32, 1])
            .dispatch([1, 1, 1]);
        let a = 128;
        let mut alu = g.create_image("alu", ImageDesc::new(a, a, HALF));
        g.simple_pass("alu", &scene.alu)
            .store(&mut alu)
            .constants(&[a, a, 128])
            .dispatch([a, a, 1]);
        g.output(&one);
        g.output(&alu);
        frames.extend(ex.run(g).unwrap());
    }
    frames.extend(ex.finish().unwrap());
    RunReport::new(
        &ctx.info,
        RunSetup::default(),
        (256, 256),
        frames,
        1,
        MemoryUse::default(),
    )
}

#[test]
fn known_cases_get_their_verdicts() {
    let report = common::with_gpu(known_cases);
    let verdict = |name: &str| {
        let p = report.passes.iter().find(|p| p.name == name).unwrap();
        p.bound_by
            .clone()
            .unwrap_or_else(|| panic!("{name} has no verdict:\n{}", report.table()))
    };
    let table = report.table();
    assert_eq!(verdict("ruler_copy").bound, Bound::Memory, "{table}");
    assert_eq!(verdict("alu").bound, Bound::Shading, "{table}");
    assert_eq!(verdict("one_texel").bound, Bound::Overhead, "{table}");
    assert_eq!(verdict("ruler_empty").bound, Bound::Overhead, "{table}");
    assert!(table.contains("bound by"), "{table}");
}

/// The work-skipped variant: the all-arithmetic pass's shader without its
/// rounds keeps a small share of its time, so the variant calls it shading;
/// passes whose shaders have no such variant get no share and keep their
/// verdicts.
#[test]
fn skipping_the_work_of_an_arithmetic_pass_leaves_little_of_its_time() {
    let (report, skipped) = common::with_gpu(|ctx| {
        let report = known_cases(ctx);
        ctx.set_skip_work(true);
        let skipped = known_cases(ctx);
        ctx.set_skip_work(false);
        (report, skipped)
    });
    let tagged: Vec<&str> = skipped
        .passes
        .iter()
        .filter(|p| p.tags.iter().any(|t| t == WORK_SKIPPED_TAG))
        .map(|p| p.name.as_str())
        .collect();
    assert_eq!(tagged, ["alu"], "only alu_heavy.comp has the variant");
    let report = report.with_work_skipped(&skipped);
    let table = report.table();
    let pass = |name: &str| report.passes.iter().find(|p| p.name == name).unwrap();
    let alu = pass("alu");
    let share = alu.work_skipped_share.expect("alu was varied");
    // 128 rounds of sin and cos per texel against none: 4-7 % on lavapipe.
    assert!(share < 0.25, "alu keeps {share} of its time\n{table}");
    let verdict = alu.bound_by.clone().unwrap();
    assert_eq!(verdict.bound, Bound::Shading, "{table}");
    assert!(verdict.why.contains("with its work skipped"), "{table}");
    for name in ["ruler_copy", "one_texel", "ruler_empty"] {
        assert_eq!(pass(name).work_skipped_share, None, "{name}");
    }
    assert_eq!(
        pass("ruler_copy").bound_by.clone().unwrap().bound,
        Bound::Memory
    );
    assert_eq!(
        pass("one_texel").bound_by.clone().unwrap().bound,
        Bound::Overhead
    );
}

/// `render --variants` on the default frame: the irradiance pass, the chain's
/// blurs and the final pass get a share (and, past the overhead and bandwidth
/// rules, a verdict from it), the others none; the image is the measured
/// runs', not the variant's.
#[test]
fn a_render_with_variants_varies_the_shaders_that_have_one() {
    use dermis::render::{render_scene, RenderOptions};
    use dermis::scene::file::SceneFile;
    use dermis::scene::Scene;
    let mut file = SceneFile::default();
    file.render.irradiance_resolution = 256;
    (file.render.width, file.render.height) = (64, 48);
    let (plain, varied) = common::with_gpu(|ctx| {
        let scene = Scene::load(file).unwrap();
        let opts = |variants| RenderOptions {
            frames: 2,
            ruler: true,
            variants,
            ..RenderOptions::default()
        };
        let plain = render_scene(ctx, &scene, &opts(false)).unwrap();
        let varied = render_scene(ctx, &scene, &opts(true)).unwrap();
        (plain, varied)
    });
    assert!(
        plain.rgba8 == varied.rgba8,
        "the variant's image leaked out"
    );
    let report = &varied.report;
    let table = report.table();
    let mut with_share = Vec::new();
    for p in &report.passes {
        if let Some(share) = p.work_skipped_share {
            assert!(
                share.is_finite() && share > 0.0,
                "{}: {share}\n{table}",
                p.name
            );
            // The overhead and bandwidth rules come first (timing::bound).
            let v = p.bound_by.as_ref().unwrap();
            assert!(
                v.why.contains("with its work skipped")
                    || matches!(v.bound, Bound::Overhead | Bound::Memory),
                "{}: {v:?}",
                p.name
            );
            with_share.push(p.name.as_str());
        }
    }
    assert!(with_share.contains(&"irradiance"), "{with_share:?}");
    assert!(with_share.contains(&"skin"), "{with_share:?}");
    assert!(
        with_share.iter().any(|n| n.starts_with("blur")),
        "{with_share:?}"
    );
    for name in ["ruler_copy", "tonemap", "skin_depth", "background"] {
        assert!(!with_share.contains(&name), "{name} has no variant");
    }
    assert!(plain
        .report
        .passes
        .iter()
        .all(|p| p.work_skipped_share.is_none()));
}
