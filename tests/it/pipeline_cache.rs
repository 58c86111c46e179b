//! The on-disk pipeline cache (src/gpu/pipeline_cache.rs): a render fills it,
//! a second render made from it is as clean under validation and
//! synchronization validation as the first, and a damaged file is a warning,
//! never a failure, and is replaced by a whole one.

use crate::common;

use dermis::render::{render_scene, RenderOptions};
use dermis::scene::file::SceneFile;
use dermis::scene::Scene;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "dermis-pipeline-cache-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The one pipeline cache file in `dir`.
fn cache_file(dir: &Path) -> PathBuf {
    let files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            name.starts_with("pipelines-") && name.ends_with(".bin")
        })
        .collect();
    assert_eq!(files.len(), 1, "one pipeline cache file in {dir:?}");
    files[0].clone()
}

/// A whole file: dermis' header (magic, length of the rest) before the data.
fn assert_whole(path: &Path) {
    let bytes = std::fs::read(path).unwrap();
    assert!(bytes.len() >= 24 + 32, "{} bytes", bytes.len());
    assert_eq!(&bytes[..8], b"dermPC01");
    let len = u64::from_le_bytes(bytes[8..16].try_into().unwrap());
    assert_eq!(len as usize, bytes.len() - 24);
}

/// A 64 × 64 render of the built-in head.
fn small_render(ctx: &std::sync::Arc<dermis::gpu::Context>) {
    let mut file = SceneFile::default();
    file.render.width = 64;
    file.render.height = 64;
    file.render.irradiance_resolution = 256;
    let scene = Scene::load(file).unwrap();
    render_scene(ctx, &scene, &RenderOptions::default()).unwrap();
}

#[test]
fn pipelines_from_the_cache_render_as_clean_as_fresh_ones() {
    let dir = folder("hit");
    let ((), log) = common::with_gpu_cache_log(Some(&dir), small_render);
    common::assert_clean(&log);
    let path = cache_file(&dir);
    assert_whole(&path);
    let ((), log) = common::with_gpu_cache_log(Some(&dir), small_render);
    common::assert_clean(&log);
    assert_eq!(cache_file(&dir), path);
    assert_whole(&path);
}

#[test]
fn a_context_without_pipelines_writes_no_cache() {
    let dir = folder("none");
    let ((), log) = common::with_gpu_cache_log(Some(&dir), |_| ());
    common::assert_clean(&log);
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
}

fn render(cache: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dermis"))
        .args(["render", "--width", "32", "--height", "32"])
        .args(["--irradiance-res", "256", "--validation", "--out"])
        .arg(cache.join("out.png"))
        .env("DERMIS_CACHE_DIR", cache)
        .output()
        .expect("dermis runs")
}

#[test]
fn a_damaged_cache_file_is_a_warning_and_is_replaced() {
    let dir = folder("damaged");
    let out = render(&dir);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let path = cache_file(&dir);
    assert_whole(&path);
    let whole = std::fs::read(&path).unwrap();
    let mut flipped = whole.clone();
    *flipped.last_mut().unwrap() ^= 1;
    for damaged in [
        b"not a cache".to_vec(),
        whole[..whole.len() / 2].to_vec(),
        flipped,
    ] {
        std::fs::write(&path, &damaged).unwrap();
        let out = render(&dir);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{stderr}");
        assert!(!stderr.contains("[validation]"), "{stderr}");
        assert!(
            stderr.contains("pipeline cache") && stderr.contains("is ignored"),
            "a warning names the damaged file: {stderr}"
        );
        assert_whole(&path);
    }
    let out = render(&dir);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("pipeline cache"), "{stderr}");
}
