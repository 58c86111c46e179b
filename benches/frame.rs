//! Per-pass GPU cost of the built-in head's frame (`--scene builtin`: under the sky,
//! 1280×720) against the irradiance resolution and the diffusion chain, with the
//! rulers: every pass is reported in ms, ns/texel, GB/s and × the copy ruler timed in
//! the same frame. Medians over warmed-up frames (the first frame of each run is
//! warm-up: lavapipe compiles shaders on first use). `cargo bench --bench frame`;
//! `DERMIS_BENCH_FRAMES` (default 4), `DERMIS_BENCH_SIZES` (irradiance sides, default
//! "512,1024,2048,4096"), `DERMIS_BENCH_CHAINS` (default "full,adaptive"),
//! `DERMIS_BENCH_LIGHTS` (`environment.lights` modes, default "0,auto": the sky's
//! sun in the SH or taken out as a soft-shadowed light, side by side) and
//! `DERMIS_BENCH_KERNEL` (`deon7` or `accurate`) tune it. Writes
//! `target/bench-frame.json` (one run report per run, each with its setup) for
//! docs/design/cost-model.md.

use dermis::gpu::{Context, ContextOptions};
use dermis::render::{render_scene, RenderOptions};
use dermis::scene::file::{Chain, LightsMode, SceneFile};
use dermis::scene::Scene;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let env = |name: &str, default: &str| std::env::var(name).unwrap_or_else(|_| default.into());
    let frames: u32 = env("DERMIS_BENCH_FRAMES", "4").parse()?;
    let sizes: Vec<u32> = env("DERMIS_BENCH_SIZES", "512,1024,2048,4096")
        .split(',')
        .map(|s| s.trim().parse())
        .collect::<Result<_, _>>()?;
    let chains: Vec<Chain> = env("DERMIS_BENCH_CHAINS", "full,adaptive")
        .split(',')
        .map(|s| clap::ValueEnum::from_str(s.trim(), true))
        .collect::<Result<_, _>>()?;
    let lights: Vec<LightsMode> = env("DERMIS_BENCH_LIGHTS", "0,auto")
        .split(',')
        .map(|s| s.trim().parse())
        .collect::<Result<_, _>>()?;
    let ctx = Context::new(&ContextOptions::from_env())?;
    let mut file = SceneFile::default();
    file.skin.kernel = clap::ValueEnum::from_str(&env("DERMIS_BENCH_KERNEL", "deon7"), true)
        .map_err(|e: String| e)?;
    let mut scene = Scene::load(file)?;
    let mut reports = Vec::new();
    for size in sizes {
        for &chain in &chains {
            for &mode in &lights {
                scene.file.render.irradiance_resolution = size;
                scene.file.skin.chain = chain;
                scene.file.environment.lights = mode;
                let opts = RenderOptions {
                    frames: frames.max(2),
                    ruler: true,
                    ..RenderOptions::default()
                };
                let r = render_scene(&ctx, &scene, &opts)?.report;
                print!("\n{}{}", r.header(), r.table());
                reports.push(r);
            }
        }
    }
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench-frame.json");
    // target/ is missing when CARGO_TARGET_DIR points elsewhere.
    std::fs::create_dir_all(path.parent().unwrap())?;
    std::fs::write(&path, serde_json::to_string_pretty(&reports)?)?;
    println!("\nwrote {}", path.display());
    Ok(())
}
