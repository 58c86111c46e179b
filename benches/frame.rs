//! Per-pass GPU cost of the default frame (built-in head under the sky) at
//! several output sizes: medians over warmed-up frames (the first frame of each
//! size is warm-up: lavapipe compiles shaders on first use).
//! `cargo bench --bench frame`; `DERMIS_BENCH_FRAMES` (default 6) and
//! `DERMIS_BENCH_SIZES` (default "512,1024,2048") tune it. Writes
//! `target/bench-frame.json` for docs/performance.md.

use dermis::gpu::{Context, ContextOptions};
use dermis::render::{render_scene, RenderOptions};
use dermis::scene::file::SceneFile;
use dermis::scene::Scene;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let frames: u32 = std::env::var("DERMIS_BENCH_FRAMES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(6);
    let sizes: Vec<u32> = std::env::var("DERMIS_BENCH_SIZES")
        .unwrap_or_else(|_| "512,1024,2048".into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let ctx = Context::new(&ContextOptions::from_env())?;
    let mut scene = Scene::load(SceneFile::default())?;
    let mut reports = Vec::new();
    for size in sizes {
        scene.file.render.width = size;
        scene.file.render.height = size;
        let opts = RenderOptions {
            frames: frames.max(2),
            ..RenderOptions::default()
        };
        let r = render_scene(&ctx, &scene, &opts)?.report;
        println!(
            "\n{size}x{size} on {} ({}), {} measured frames, LP_NUM_THREADS={}",
            r.device,
            r.driver,
            r.frames - r.warmup_frames,
            r.lp_num_threads.as_deref().unwrap_or("unset")
        );
        if let Some(m) = &r.median {
            print!("{}", m.table());
        }
        reports.push(r);
    }
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench-frame.json");
    std::fs::write(&path, serde_json::to_string_pretty(&reports)?)?;
    println!("\nwrote {}", path.display());
    Ok(())
}
