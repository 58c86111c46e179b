//! Per-pass GPU cost of the built-in head's frame (`--scene builtin`: under the sky,
//! 1280×720) against the irradiance (blur) resolution: medians over warmed-up frames (the
//! first frame of each resolution is warm-up: lavapipe compiles shaders on first
//! use). `cargo bench --bench frame`; `DERMIS_BENCH_FRAMES` (default 4),
//! `DERMIS_BENCH_SIZES` (irradiance sides, default "512,1024,2048,4096") and
//! `DERMIS_BENCH_KERNEL` (`deon7` or `accurate`) tune it. Writes
//! `target/bench-frame.json` (one run report per size, each with its setup) for
//! docs/performance.md.

use dermis::gpu::{Context, ContextOptions};
use dermis::render::{render_scene, RenderOptions};
use dermis::scene::file::SceneFile;
use dermis::scene::Scene;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let frames: u32 = std::env::var("DERMIS_BENCH_FRAMES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(4);
    let sizes: Vec<u32> = std::env::var("DERMIS_BENCH_SIZES")
        .unwrap_or_else(|_| "512,1024,2048,4096".into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let ctx = Context::new(&ContextOptions::from_env())?;
    let mut file = SceneFile::default();
    if std::env::var("DERMIS_BENCH_KERNEL").as_deref() == Ok("accurate") {
        file.skin.kernel = dermis::scene::file::Kernel::Accurate;
    }
    let mut scene = Scene::load(file)?;
    let mut reports = Vec::new();
    for size in sizes {
        scene.file.render.irradiance_resolution = size;
        let opts = RenderOptions {
            frames: frames.max(2),
            ..RenderOptions::default()
        };
        let r = render_scene(&ctx, &scene, &opts)?.report;
        print!("\n{}{}", r.header(), r.table());
        reports.push(r);
    }
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench-frame.json");
    // target/ is missing when CARGO_TARGET_DIR points elsewhere.
    std::fs::create_dir_all(path.parent().unwrap())?;
    std::fs::write(&path, serde_json::to_string_pretty(&reports)?)?;
    println!("\nwrote {}", path.display());
    Ok(())
}
