//! The bound-by verdict on its known cases: the ruler copy is memory-bound, an
//! all-arithmetic pass is shading-bound, a 1-texel dispatch is overhead.

use crate::common;

use dermis::gpu::{ImageDesc, Pipelines, Sampler};
use dermis::graph::{Executor, Graph};
use dermis::testscene::{TestScene, HALF};
use dermis::timing::{Bound, MemoryUse, RunReport, RunSetup};
use std::sync::Arc;

#[test]
fn known_cases_get_their_verdicts() {
    let report = common::with_gpu(|ctx| {
        let scene = TestScene::new(ctx).unwrap();
        let pipelines = Pipelines::new(ctx);
        let sampler = Arc::new(Sampler::clamped(ctx, false).unwrap());
        let mut ex = Executor::new(ctx, 2).unwrap();
        ex.set_counters(true).unwrap();
        let mut frames = Vec::new();
        // Medians of 15 measured frames: with 5, a loaded machine's
        // preemptions reached the median (ruler_empty 2.4 ms, its minimum 0.13).
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
    });
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
