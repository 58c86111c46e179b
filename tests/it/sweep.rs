//! Time against quality: `dermis sweep` as users run it (outputs parse and name
//! every pass), and the adaptive chain's final image against the full chain's.

use crate::common;

use dermis::render::{render_scene, RenderOptions, View};
use dermis::scene::file::{load_scene, Chain};
use dermis::scene::Scene;
use dermis::sweep::metric::{compare, coverage_mask};
use std::path::Path;
use std::process::{Command, Output};

fn dermis(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dermis"))
        .args(args)
        .arg("--validation")
        .output()
        .expect("dermis runs")
}

#[test]
fn sweep_writes_csv_json_and_plots_naming_every_pass() {
    let dir = std::env::temp_dir().join(format!("dermis-sweep-{}", std::process::id()));
    let out = dermis(&[
        "sweep",
        "--scene",
        "builtin",
        "--resolutions",
        "256",
        "--kernels",
        "deon7",
        "--chains",
        "full,adaptive",
        "--reference-resolution",
        "512",
        "--width",
        "96",
        "--height",
        "96",
        "--frames",
        "2",
        "--out-dir",
        dir.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("[validation]"), "{stderr}");

    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("sweep.json")).unwrap()).unwrap();
    let points = json["points"].as_array().unwrap();
    assert_eq!(points.len(), 2);
    assert_eq!(json["reference"]["resolution"], 512);
    assert_eq!(json["reference"]["kernel"], "accurate");
    let csv = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<String> = common::csv_fields(lines.next().unwrap());
    let rows: Vec<Vec<String>> = lines.map(common::csv_fields).collect();
    assert!(rows.iter().all(|r| r.len() == header.len()), "ragged CSV");
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    for p in points {
        let chain = p["chain"].as_str().unwrap();
        let names: Vec<&str> = p["passes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s["name"].as_str().unwrap())
            .collect();
        for pass in ["irradiance", "skin", "ruler_copy", "ruler_read"] {
            assert!(names.contains(&pass), "{chain}: no {pass} in {names:?}");
        }
        // Every pass of the JSON has its CSV row, with this point's error.
        for name in names.iter().chain(&["total"]) {
            let row = rows
                .iter()
                .find(|r| r[col("chain")] == chain && r[col("pass")] == *name)
                .unwrap_or_else(|| panic!("{chain}: no CSV row for {name}"));
            let rmse: f64 = row[col("final_rmse_rel")].parse().unwrap();
            assert!((rmse - p["final_error"]["rmse_rel"].as_f64().unwrap()).abs() < 1e-12);
        }
        let rmse = p["final_error"]["rmse_rel"].as_f64().unwrap();
        assert!(rmse > 0.0 && rmse < 0.2, "{chain}: {rmse}");
        let ruler = p["passes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["name"] == "ruler_copy")
            .unwrap();
        assert_eq!(ruler["texels"], 256 * 256);
        assert_eq!(ruler["x_ruler"], 1.0);
    }
    for stem in ["time_vs_error", "passes"] {
        let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).unwrap();
        assert!(svg.contains("<svg"), "{stem}.svg");
        let png = image::open(dir.join(format!("{stem}.png")))
            .unwrap()
            .to_rgb8();
        let distinct: std::collections::HashSet<_> = png.pixels().map(|p| p.0).collect();
        assert!(distinct.len() > 4, "{stem}.png is blank");
    }
}

#[test]
fn sweep_help_documents_its_options_and_bad_values_exit_2() {
    let out = dermis(&["sweep", "--help"]);
    let help = String::from_utf8_lossy(&out.stdout);
    for flag in [
        "--resolutions",
        "--kernels",
        "--chains",
        "--reference-resolution",
        "--frames",
        "--out-dir",
    ] {
        assert!(help.contains(flag), "--help lacks {flag}:\n{help}");
    }
    let out = dermis(&[
        "sweep",
        "--resolutions",
        "300",
        "--out-dir",
        "/nonexistent/x",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("300"), "{stderr}");
}

#[test]
fn the_adaptive_chain_stays_within_one_percent_of_the_full_chain() {
    // The lit close-up (shadow edges, normal-map detail), small and without
    // occlusion to keep the test short. The adaptive chain's first level is
    // the irradiance evaluated per pixel, the full chain's a texture of 0.6 mm
    // texels: 0.84 % apart (under 0.5 %, this test's bound before, when both
    // read the texture). Against the sweep's 4096² reference the adaptive
    // chain is the closer of the two (docs/records/2026-11-26-unblurred-levels-per-pixel.md, "The unblurred
    // levels per pixel").
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scenes/close-up-lights.toml");
    let mut file = load_scene(&path).unwrap();
    file.render.width = 320;
    file.render.height = 180;
    file.render.irradiance_resolution = 1024;
    file.render.skybox = false;
    file.skin.occlusion = dermis::scene::file::Occlusion::Off;
    let (full, adaptive) = common::with_gpu(|ctx| {
        let mut scene = Scene::load(file).unwrap();
        let mut image = |chain| {
            scene.file.skin.chain = chain;
            let opts = RenderOptions {
                hdr: true,
                view: View::FINAL,
                ..RenderOptions::default()
            };
            render_scene(ctx, &scene, &opts).unwrap().hdr.unwrap()
        };
        (image(Chain::Full), image(Chain::Adaptive))
    });
    let e = compare(&full, &adaptive, &coverage_mask(&full)).unwrap();
    println!("adaptive against full at 1024²: {e:?}");
    assert!(e.pixels > 10_000, "{e:?}");
    assert!(e.rmse_rel > 0.0, "the chains should differ: {e:?}");
    assert!(e.rmse_rel < 0.01, "{e:?}");
}
