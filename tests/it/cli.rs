//! The command line as users run it, with validation on: outputs, reports, and
//! clean failures (exit status 2, one line naming the problem) for bad input.

use crate::common;

use std::path::PathBuf;
use std::process::{Command, Output};

fn dermis(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dermis"))
        .args(args)
        .arg("--validation")
        .output()
        .expect("dermis runs")
}

/// `render` at 32 × 32 with a 256² irradiance texture: the smallest frame
/// the tests of the command line need.
const SMALL_RENDER: [&str; 7] = [
    "render",
    "--width",
    "32",
    "--height",
    "32",
    "--irradiance-res",
    "256",
];

/// [`dermis`] of [`SMALL_RENDER`] and `args`.
fn small_render(args: &[&str]) -> Output {
    dermis(&[&SMALL_RENDER[..], args].concat())
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("dermis-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn assert_no_validation_messages(out: &Output) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !stderr.contains("[validation]"),
        "validation messages:\n{stderr}"
    );
}

#[test]
fn render_writes_png_report_and_graph() {
    let png = tmp("out.png");
    let json = tmp("report.json");
    let out = dermis(&[
        "render",
        "--out",
        png.to_str().unwrap(),
        "--irradiance-res",
        "256",
        "--width",
        "80",
        "--height",
        "48",
        "--frames",
        "3",
        "--timings",
        "--dump-graph",
        "--report",
        json.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_no_validation_messages(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("barrier"), "--dump-graph prints barriers");
    assert!(
        stdout.contains("frame (GPU span)"),
        "--timings prints the table"
    );
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (80, 48));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(report["frames"], 3);
    assert_eq!(report["warmup_frames"], 1);
    let passes = report["median"]["passes"].as_array().unwrap();
    assert!(passes.iter().all(|p| p["gpu_ns"].as_f64().unwrap() > 0.0));
    assert!(report["fingerprint"]["device"]
        .as_str()
        .is_some_and(|d| !d.is_empty()));
}

#[test]
fn render_writes_self_describing_report_trace_and_csv() {
    let (json, trace, csv) = (tmp("r.json"), tmp("t.json"), tmp("c.csv"));
    let out = dermis(&[
        "render",
        "--out",
        tmp("describe.png").to_str().unwrap(),
        "--irradiance-res",
        "256",
        "--width",
        "64",
        "--height",
        "48",
        "--frames",
        "3",
        "--report",
        json.to_str().unwrap(),
        "--trace",
        trace.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_no_validation_messages(&out);
    let read = |p: &PathBuf| std::fs::read_to_string(p).unwrap();

    // The report says what ran.
    let r: serde_json::Value = serde_json::from_str(&read(&json)).unwrap();
    let setup = &r["setup"];
    assert_eq!(setup["irradiance_resolution"], 256);
    assert_eq!(setup["view"], "final");
    assert_eq!(setup["kernel"], "deon7");
    assert_eq!(setup["chain"], "adaptive");
    assert!(
        setup["scene"]
            .as_str()
            .is_some_and(|s| s.ends_with("assets/default.toml")),
        "{setup}"
    );
    // The default scene's mesh: "builtin" or the scan's path.
    assert!(setup["mesh"].as_str().is_some_and(|m| !m.is_empty()));
    assert_eq!(
        (
            setup["render_width"].clone(),
            setup["render_height"].clone()
        ),
        (64.into(), 48.into())
    );
    assert!(setup["environment"].as_str().is_some_and(|e| !e.is_empty()));
    assert!(setup["occlusion"].is_string());
    assert_eq!(r["dermis_version"], env!("CARGO_PKG_VERSION"));
    assert!(r["git_commit"].as_str().is_some_and(|c| !c.is_empty()));
    let fp = &r["fingerprint"];
    assert!(fp["clock"] == "host-fence" || fp["clock"] == "gpu-timestamp");
    assert!(fp["cpu_model"].as_str().is_some_and(|c| !c.is_empty()));
    assert!(fp["cpu_cores"].as_u64().is_some_and(|c| c >= 1));
    assert_eq!(fp["validation"], true);
    // Enough to reproduce: the command line, when, from which sources.
    assert_eq!(r["schema_version"], dermis::timing::SCHEMA_VERSION);
    let args = r["command_line"].as_array().unwrap();
    assert!(args.iter().any(|a| a == "--irradiance-res"), "{args:?}");
    assert!(r["timestamp"].as_str().is_some_and(|t| t.ends_with('Z')));
    assert!(r["git_dirty"].is_boolean());
    assert!(r["run_id"].as_str().is_some_and(|id| !id.is_empty()));
    for key in ["gamma", "skybox", "background", "uv_origin", "mm_per_unit"] {
        assert!(setup.get(key).is_some(), "setup lacks {key}: {setup}");
    }
    assert!(setup["camera"]["fov_y_deg"]
        .as_f64()
        .is_some_and(|f| f > 0.0));
    let memory = &r["memory"];
    let bytes = |k: &str| memory[k].as_u64().unwrap();
    assert!(bytes("transient_pool_bytes") > 0);
    assert!(bytes("allocated_bytes") >= bytes("transient_pool_bytes"));
    assert!(bytes("reserved_bytes") >= bytes("allocated_bytes"));
    let passes = r["passes"].as_array().unwrap();
    assert!(passes.len() > 5);
    for p in passes {
        assert_eq!(p["frames"], 2, "{p}");
        let v = |k: &str| p[k].as_f64().unwrap();
        assert!(
            v("min_ns") <= v("median_ns") && v("median_ns") <= v("p90_ns"),
            "{p}"
        );
        assert!(v("p90_ns") <= v("max_ns"), "{p}");
        assert!(
            v("min_ns") <= v("mean_ns") && v("mean_ns") <= v("max_ns"),
            "{p}"
        );
        assert!(v("std_ns") >= 0.0, "{p}");
        assert_eq!(p["samples_ns"].as_array().unwrap().len(), 2, "{p}");
    }
    let frames = r["per_frame"].as_array().unwrap();
    assert_eq!(frames.len(), 3);
    assert!(frames
        .iter()
        .flat_map(|f| f["passes"].as_array().unwrap())
        .all(|p| p["start_ns"].as_f64().is_some_and(|s| s >= 0.0)));

    // The trace parses; every pass lies in its frame, passes of a frame apart.
    let t: serde_json::Value = serde_json::from_str(&read(&trace)).unwrap();
    let events = t["traceEvents"].as_array().unwrap();
    let of = |cat: &'static str| events.iter().filter(move |e| e["cat"] == cat);
    let span = |e: &serde_json::Value| {
        assert_eq!(e["ph"], "X");
        let ts = e["ts"].as_f64().unwrap();
        (ts, ts + e["dur"].as_f64().unwrap())
    };
    const EPS: f64 = 1e-6; // µs
    assert_eq!(of("frame").count(), 3);
    for (f, report) in of("frame").zip(frames) {
        let (f0, f1) = span(f);
        let mut inside: Vec<_> = of("pass")
            .filter(|p| p["args"]["frame"] == f["args"]["frame"])
            .map(span)
            .collect();
        assert_eq!(inside.len(), report["passes"].as_array().unwrap().len());
        inside.sort_by(|a, b| a.0.total_cmp(&b.0));
        for &(p0, p1) in &inside {
            assert!(
                f0 <= p0 + EPS && p1 <= f1 + EPS,
                "{p0}..{p1} outside {f0}..{f1}"
            );
        }
        for w in inside.windows(2) {
            assert!(w[0].1 <= w[1].0 + EPS, "overlap: {w:?}");
        }
    }

    // The CSV: a header, then one row per pass per frame, every row complete.
    let text = read(&csv);
    let lines: Vec<&str> = text.lines().collect();
    let header = common::csv_fields(lines[0]);
    for column in [
        "frame",
        "pass",
        "start_ns",
        "duration_ns",
        "clock",
        "irradiance_resolution",
        "kernel",
        "view",
        "run_id",
        "run",
        "scene",
        "environment",
        "device",
        "git_commit",
    ] {
        assert!(header.iter().any(|h| h == column), "{column} in {header:?}");
    }
    let per_frame: Vec<usize> = frames
        .iter()
        .map(|f| f["passes"].as_array().unwrap().len())
        .collect();
    // Frames after the first run the same passes (the first also prefilters).
    assert_eq!(per_frame[1], per_frame[2]);
    assert!(per_frame[0] >= per_frame[1]);
    assert_eq!(lines.len() - 1, per_frame.iter().sum::<usize>());
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let mut rows_per_frame = [0usize; 3];
    for line in &lines[1..] {
        let row = common::csv_fields(line);
        assert_eq!(row.len(), header.len(), "{line}");
        assert_eq!(row[col("irradiance_resolution")], "256");
        assert_eq!(row[col("view")], "final");
        // Concatenated runs stay apart: every row names its run and machine.
        assert_eq!(row[col("run_id")], r["run_id"].as_str().unwrap());
        assert_eq!(row[col("device")], fp["device"].as_str().unwrap());
        assert!(row[col("scene")].ends_with("default.toml"), "{line}");
        rows_per_frame[row[col("frame")].parse::<usize>().unwrap()] += 1;
    }
    assert_eq!(rows_per_frame.to_vec(), per_frame);
}

#[test]
fn counters_reach_the_table_report_csv_and_trace() {
    let (json, trace, csv) = (tmp("k.json"), tmp("k-trace.json"), tmp("k.csv"));
    let out = dermis(&[
        "render",
        "--scene",
        "builtin",
        "--out",
        tmp("counters.png").to_str().unwrap(),
        "--irradiance-res",
        "256",
        "--width",
        "64",
        "--height",
        "48",
        "--frames",
        "2",
        "--ruler",
        "--counters",
        "--timings",
        "--report",
        json.to_str().unwrap(),
        "--trace",
        trace.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_no_validation_messages(&out);
    assert!(stdout.contains("work counters per frame"), "{stdout}");
    assert!(stdout.contains("bound by"), "{stdout}");
    let read = |p: &PathBuf| std::fs::read_to_string(p).unwrap();
    let r: serde_json::Value = serde_json::from_str(&read(&json)).unwrap();
    assert_eq!(r["fingerprint"]["counters"], true);
    let copy = r["passes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "ruler_copy")
        .unwrap();
    assert_eq!(copy["counters"]["compute_invocations"], 256 * 256);
    assert_eq!(copy["bound_by"]["bound"], "memory");
    // The CSV's last column: the copy's invocations in every row of it.
    let text = read(&csv);
    let rows: Vec<&str> = text
        .lines()
        .filter(|l| l.contains(",ruler_copy,"))
        .collect();
    assert_eq!(rows.len(), 2);
    assert!(rows.iter().all(|l| l.ends_with(",65536")), "{rows:?}");
    let t: serde_json::Value = serde_json::from_str(&read(&trace)).unwrap();
    let counters = t["traceEvents"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["ph"] == "C")
        .count();
    assert!(counters > 0, "no counter track");
}

#[test]
fn info_json_describes_the_device() {
    let out = dermis(&["info", "--json"]);
    assert!(out.status.success());
    assert_no_validation_messages(&out);
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(info["max_image_dimension_2d"].as_u64().unwrap() >= 4096);
    assert_eq!(info["validation"], true);
}

#[test]
fn target_larger_than_the_device_allows_is_a_clean_error() {
    let out = dermis(&[
        "render",
        "--out",
        tmp("big.png").to_str().unwrap(),
        "--width",
        "1000000",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert_no_validation_messages(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("1000000") && stderr.contains("16384"),
        "{stderr}"
    );
}

#[test]
fn unknown_output_format_is_a_clean_error() {
    let out = dermis(&[
        "render",
        "--out",
        tmp("x.bmp").to_str().unwrap(),
        "--width",
        "16",
        "--height",
        "16",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("x.bmp") && stderr.contains("unsupported output format"),
        "{stderr}"
    );
}

/// Every output is checked before any work: with a device that does not
/// exist, the error is still the output's, so the device was never opened.
/// Nothing is created.
#[test]
fn bad_outputs_are_refused_before_the_device_is_opened() {
    let folder = tmp("a-folder.json");
    std::fs::create_dir_all(&folder).unwrap();
    let file = tmp("a-file.txt");
    std::fs::write(&file, "x").unwrap();
    let (folder, file) = (folder.to_str().unwrap(), file.to_str().unwrap());
    let in_file = format!("{file}/r.json");
    let (sheet, shot, csv) = (tmp("sheet.exr"), tmp("shot.jpg"), tmp("c.txt"));
    let (sheet, shot, csv) = (
        sheet.to_str().unwrap(),
        shot.to_str().unwrap(),
        csv.to_str().unwrap(),
    );
    let cases: Vec<(Vec<&str>, &str, &str)> = vec![
        (
            vec!["render", "--report", "/no/such/dir/r.json"],
            "--report",
            "does not exist",
        ),
        (
            vec!["render", "--out", "/no/such/dir/x.png"],
            "--out",
            "does not exist",
        ),
        (
            vec!["render", "--debug-sheet", sheet],
            "--debug-sheet",
            "use .png)",
        ),
        (
            vec!["render", "--compare-occlusion", sheet],
            "--compare-occlusion",
            "use .png)",
        ),
        (vec!["render", "--trace", folder], "--trace", "is a folder"),
        (vec!["render", "--csv", csv], "--csv", "use .csv)"),
        (vec!["sweep", "--out-dir", file], "--out-dir", "is a file"),
        (
            vec!["reference", "--out-dir", file],
            "--out-dir",
            "is a file",
        ),
        (
            vec!["view", "--screenshot", shot],
            "--screenshot",
            "use .png)",
        ),
        (
            vec!["interleave", "--runs", "1", "--out-dir", file],
            "--out-dir",
            "is a file",
        ),
        (
            vec!["compare", "no-base.json", "no-new.json", "--junit", csv],
            "--junit",
            "use .xml)",
        ),
        (
            vec!["export", "no-report.json", "--bencher", folder],
            "--bencher",
            "is a folder",
        ),
        // A trailing slash names a folder, for every output flag.
        (vec!["render", "--out", "new.png/"], "--out", "is a folder"),
        (
            vec!["render", "--debug-sheet", "new.png/"],
            "--debug-sheet",
            "is a folder",
        ),
        (vec!["render", "--csv", "new.csv/"], "--csv", "is a folder"),
        // A folder where nothing can be created; a file taken for a folder.
        (
            vec!["render", "--out", "/proc/x.png"],
            "--out",
            "cannot create a file in /proc",
        ),
        (
            vec!["render", "--report", &in_file],
            "--report",
            "is not a folder",
        ),
    ];
    for (args, flag, why) in cases {
        let path = args.last().copied().unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_dermis"))
            .args(&args)
            .args(["--device", "no-such-gpu-xyz"])
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .expect("dermis runs");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        let line = stderr
            .lines()
            .find(|l| l.starts_with("error:"))
            .unwrap_or_default();
        assert!(
            line.contains(&format!("{flag} {path}")) && line.contains(why),
            "{args:?}: {stderr}"
        );
        assert!(!stderr.contains("no-such-gpu-xyz"), "{args:?}: {stderr}");
    }
    for created in [sheet, shot, csv, "new.png", "new.csv"] {
        assert!(!std::path::Path::new(created).exists(), "{created}");
    }
    assert!(!std::path::Path::new("/no/such/dir").exists());
}

#[test]
fn unknown_device_is_a_clean_error() {
    let out = dermis(&["info", "--device", "no-such-gpu-xyz"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("no-such-gpu-xyz") && stderr.contains("available"),
        "{stderr}"
    );
}

#[test]
fn no_driver_names_what_to_install() {
    // The loader finds no driver: dermis must say what to install (no validation
    // here: the loader itself reports the missing driver through the layer).
    let out = Command::new(env!("CARGO_BIN_EXE_dermis"))
        .arg("info")
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .output()
        .expect("dermis runs");
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("no Vulkan device found") && stderr.contains("mesa-vulkan-drivers"),
        "{stderr}"
    );
}

/// Runs `render` on bad input: exit status 2, one error line naming `needle`,
/// no panic.
fn assert_bad_input(args: &[&str], needle: &str) {
    let out = dermis(
        &[
            &[
                "render",
                "--out",
                tmp("bad.png").to_str().unwrap(),
                "--width",
                "32",
                "--height",
                "32",
            ],
            args,
        ]
        .concat(),
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let line = stderr
        .lines()
        .find(|l| l.starts_with("error:"))
        .unwrap_or_default();
    assert!(line.contains(needle), "{args:?}: {stderr}");
}

#[test]
fn bad_scene_input_is_a_clean_error() {
    let glb = tmp("truncated.glb");
    let bytes = std::fs::read(dermis::assets::scan().join("LeePerrySmith.glb")).unwrap();
    std::fs::write(&glb, &bytes[..bytes.len() / 3]).unwrap();
    assert_bad_input(&["--mesh", glb.to_str().unwrap()], "truncated.glb");

    let hdr = tmp("corrupt.hdr");
    std::fs::write(
        &hdr,
        b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 512 +X 1024\n\x02\x02",
    )
    .unwrap();
    assert_bad_input(&["--env", hdr.to_str().unwrap()], "corrupt.hdr");

    let toml = tmp("unknown.toml");
    std::fs::write(&toml, "[render]\nwidth = 64\nfov = 3\n").unwrap();
    assert_bad_input(&["--scene", toml.to_str().unwrap()], "line 3");

    let toml = tmp("missing-texture.toml");
    std::fs::write(&toml, "[textures]\nalbedo = \"no-such-albedo.png\"\n").unwrap();
    assert_bad_input(&["--scene", toml.to_str().unwrap()], "no-such-albedo.png");

    assert_bad_input(&["--env", "uniform:1,nan,1"], "uniform");
    assert_bad_input(&["--irradiance-res", "3000"], "irradiance_resolution");
    assert_bad_input(
        &["--env-lights", "many"],
        "invalid value 'many' for '--env-lights",
    );
    assert_bad_input(
        &["--uv-origin", "upper-left"],
        "invalid value 'upper-left' for '--uv-origin",
    );
}

#[test]
fn bad_post_and_blur_settings_name_their_key() {
    assert_bad_input(&["--glow-intensity", "-1"], "render.glow_intensity = -1");
    assert_bad_input(
        &["--tone-curve", "sepia"],
        "invalid value 'sepia' for '--tone-curve",
    );
    assert_bad_input(&["--blur-width", "-0.5"], "skin.blur_width = -0.5");
    assert_bad_input(&["--blur-amount", "2"], "skin.blur_amount = 2");
    assert_bad_input(&["--transmission", "-1"], "skin.transmission = -1");
    assert_bad_input(&["--transmission", "NaN"], "skin.transmission = NaN");
    assert_bad_input(&["--background", "2,0,0"], "render.background.r = 2");
    assert_bad_input(&["--background", "1,0"], "expected three numbers R,G,B");
    assert_bad_input(&["--glow", "maybe"], "invalid value 'maybe' for '--glow");
    let toml = tmp("bad-post.toml");
    std::fs::write(&toml, "[render]\nglow_intensity = -2\n").unwrap();
    assert_bad_input(
        &["--scene", toml.to_str().unwrap()],
        "render.glow_intensity = -2",
    );
    std::fs::write(&toml, "[render]\ntone_curve = \"sepia\"\n").unwrap();
    assert_bad_input(&["--scene", toml.to_str().unwrap()], "line 2");
    std::fs::write(&toml, "[skin]\nblur_width = -1\n").unwrap();
    assert_bad_input(&["--scene", toml.to_str().unwrap()], "skin.blur_width = -1");
    assert_bad_input(
        &["--debug-sheet", tmp("sheet.jpg").to_str().unwrap()],
        "unsupported output format",
    );
}

/// `export` refuses a report of a schema newer than it reads, as `compare`
/// does, writing nothing.
#[test]
fn export_refuses_an_unknown_schema_version() {
    let report = tmp("schema-99.json");
    std::fs::write(&report, r#"{"schema_version": 99, "per_frame": []}"#).unwrap();
    let bencher = tmp("bencher-99.json");
    let out = Command::new(env!("CARGO_BIN_EXE_dermis"))
        .args(["export", report.to_str().unwrap(), "--bencher"])
        .arg(&bencher)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("schema-99.json: report schema 99 is newer than this dermis reads"),
        "{stderr}"
    );
    assert!(!bencher.exists());
}

/// Two output flags naming one file would overwrite each other: refused
/// before any work, also through a symbolic link.
#[test]
fn two_outputs_naming_one_file_are_refused() {
    let c = tmp("one.png");
    let link = tmp("link-to-one.png");
    let _ = std::fs::remove_file(&link);
    std::os::unix::fs::symlink(&c, &link).unwrap();
    let (c, link) = (c.to_str().unwrap(), link.to_str().unwrap());
    for args in [
        vec!["render", "--compare-occlusion", c, "--out", c],
        vec!["render", "--out", c, "--debug-sheet", link],
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_dermis"))
            .args(&args)
            .args(["--device", "no-such-gpu-xyz"])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains("name one file"), "{args:?}: {stderr}");
        assert!(!stderr.contains("no-such-gpu-xyz"), "{stderr}");
    }
}

/// Pre-exposure: the same scene lit 1e-30 … 1e30 times as brightly (by
/// `environment.intensity`, the sky's own intensity, or the map's radiance)
/// renders the same 8-bit image at the matching exposure, within rounding.
#[test]
fn any_finite_intensity_renders_the_same_image_at_the_matching_exposure() {
    let render = |name: &str, scene: &str, args: &[&str], ev: f64| {
        let toml = tmp(&format!("{name}.toml"));
        std::fs::write(&toml, scene).unwrap();
        let png = tmp(&format!("{name}.png"));
        let ev = format!("{ev}");
        let out = small_render(
            &[
                &[
                    "--scene",
                    toml.to_str().unwrap(),
                    "--out",
                    png.to_str().unwrap(),
                ],
                args,
                &["--exposure", &ev],
            ]
            .concat(),
        );
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_no_validation_messages(&out);
        image::open(&png).unwrap().to_rgba8()
    };
    let base = render("i1", "[environment]\nintensity = 1\n", &[], 0.0);
    let lit = base
        .pixels()
        .filter(|p| p.0[..3].iter().any(|&c| c > 16))
        .count();
    assert!(lit > 100, "the base image shows the head: {lit} pixels lit");
    for (name, scene, args, factor) in [
        (
            "i1e-30",
            "[environment]\nintensity = 1e-30\n",
            &[][..],
            1e-30,
        ),
        ("i1e-6", "[environment]\nintensity = 1e-6\n", &[], 1e-6),
        ("i1e6", "[environment]\nintensity = 1e6\n", &[], 1e6),
        ("i1e30", "[environment]\nintensity = 1e30\n", &[], 1e30),
        ("sky1e-30", "", &["--env", "sky:intensity=1e-30"][..], 1e-30),
    ] {
        // The factor as the file holds it (f32).
        let ev = -f64::from(factor as f32).log2();
        let img = render(name, scene, args, ev);
        let worst = base
            .pixels()
            .zip(img.pixels())
            .flat_map(|(a, b)| (0..3).map(move |c| a.0[c].abs_diff(b.0[c])))
            .max()
            .unwrap();
        assert!(
            worst <= 1,
            "{name} at {ev:+.3} EV: off by {worst} levels of 255"
        );
    }
}

/// An exposure whose image cannot be represented (inf/NaN or zeros in the
/// EXR) is refused naming the bound; a head off-screen says so.
#[test]
fn exposures_beyond_floats_are_refused_and_an_empty_frame_is_said() {
    assert_bad_input(
        &["--exposure", "200"],
        "render.exposure = 200: must be in -100..=100 EV",
    );
    assert_bad_input(&["--exposure", "-200"], "render.exposure = -200");
    for mm in ["1e-6", "1e6"] {
        let out = small_render(&[
            "--out",
            tmp("off-screen.png").to_str().unwrap(),
            "--mm-per-unit",
            mm,
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{mm}: {stderr}");
        assert!(
            stderr.contains("warning: the mesh covers no pixel"),
            "{mm}: {stderr}"
        );
        assert!(
            String::from_utf8_lossy(&out.stdout).contains("nothing covered to meter"),
            "{mm}"
        );
    }
    // A given exposure far too low: the image is black, and that is said.
    let out = small_render(&[
        "--out",
        tmp("black.png").to_str().unwrap(),
        "--exposure",
        "-60",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("the image is black"), "{stderr}");
}

#[test]
fn debug_sheet_comparison_and_post_settings_from_the_command_line() {
    let (png, sheet, comparison, json) = (
        tmp("post.png"),
        tmp("sheet.png"),
        tmp("occlusion.png"),
        tmp("post.json"),
    );
    let out = dermis(&[
        "render",
        "--out",
        png.to_str().unwrap(),
        "--irradiance-res",
        "256",
        "--width",
        "96",
        "--height",
        "120",
        "--tone-curve",
        "neutral",
        "--glow",
        "on",
        "--glow-intensity",
        "0.5",
        "--skybox",
        "off",
        "--background",
        "0.2,0.3,0.4",
        "--blur-width",
        "2",
        "--blur-amount",
        "0.8",
        "--test-texture",
        "on",
        "--debug-sheet",
        sheet.to_str().unwrap(),
        "--compare-occlusion",
        comparison.to_str().unwrap(),
        "--report",
        json.to_str().unwrap(),
        "--timings",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_no_validation_messages(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("EV, metered)"), "{stdout}");
    assert!(stdout.contains("tone curve neutral, glow 0.5"), "{stdout}");
    // The glow's passes are timed on their own.
    for pass in [
        "meter",
        "meter_reduce",
        "glow_down1",
        "glow1_u",
        "glow2_v",
        "glow",
    ] {
        assert!(
            stdout.contains(&format!("\n{pass} ")),
            "no {pass} in\n{stdout}"
        );
    }
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let setup = &r["setup"];
    assert_eq!(setup["tone_curve"], "neutral");
    assert_eq!(setup["glow_intensity"], 0.5);
    assert_eq!(setup["blur_width"], 2.0);
    assert_eq!(setup["blur_amount"], 0.8);
    assert_eq!(setup["test_texture"], true);
    assert_eq!(setup["exposure_metered"], true);
    assert!(setup["exposure_ev"].as_f64().is_some_and(f64::is_finite));
    // The background shows where the mesh does not: the top-left corner.
    let img = image::open(&png).unwrap().to_rgba8();
    let corner = img.get_pixel(0, 0).0;
    assert!(
        (corner[2] as i32 - 170).abs() < 6 && corner[0] < corner[1],
        "{corner:?}"
    );
    let (w, h) = image::image_dimensions(&sheet).unwrap();
    assert_eq!(w, 6 * 256, "{w}x{h}");
    assert_eq!(image::image_dimensions(&comparison).unwrap().0, 2 * 96);
}

#[test]
fn views_write_intermediates() {
    // UV-space views come out at the irradiance resolution, floats kept in EXR.
    let exr = tmp("stretch.exr");
    let out = dermis(&[
        "render",
        "--view",
        "stretch",
        "--irradiance-res",
        "256",
        "--width",
        "64",
        "--height",
        "64",
        "--out",
        exr.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_no_validation_messages(&out);
    let img = exr::prelude::read_first_rgba_layer_from_file(
        &exr,
        |res, _| (res.width(), res.height(), Vec::new()),
        |(_, _, px): &mut (usize, usize, Vec<[f32; 4]>), _, (r, g, b, a): (f32, f32, f32, f32)| {
            px.push([r, g, b, a])
        },
    )
    .unwrap();
    let (w, h, px) = &img.layer_data.channel_data.pixels;
    assert_eq!((*w, *h), (256, 256));
    // Covered texels hold texels-per-mm: positive, finite, and the atlas is ~1 texel/mm at 256².
    let covered: Vec<_> = px.iter().filter(|p| p[3] > 0.5).collect();
    assert!(covered.len() > 256 * 256 / 10);
    assert!(covered
        .iter()
        .all(|p| p[0] > 0.0 && p[0].is_finite() && p[1] > 0.0));
    for view in [
        "blur6",
        "irradiance",
        "stretch3",
        "diffuse",
        "specular",
        "direct",
        "occlusion",
        "depth",
        "normals",
        "albedo",
        "regions",
        "test-texture",
        "prefiltered",
    ] {
        let png = tmp(&format!("{view}.png"));
        let out = dermis(&[
            "render",
            "--view",
            view,
            "--irradiance-res",
            "256",
            "--width",
            "64",
            "--height",
            "48",
            "--out",
            png.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{view}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let size = image::image_dimensions(&png).unwrap();
        let want = match view {
            "blur6" | "irradiance" | "stretch3" => (256, 256),
            "prefiltered" => (128, 512),
            _ => (64, 48),
        };
        assert_eq!(size, want, "{view}");
    }
    let out = dermis(&[
        "render",
        "--view",
        "blur7",
        "--out",
        tmp("x.png").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    // Views are the frame graph's images: an unknown one is refused before
    // any frame is rendered, naming how to list them.
    assert!(
        stderr.contains("--view blur7: no such view") && stderr.contains("--view list"),
        "{stderr}"
    );
}

#[test]
fn sh_prints_the_projection_of_a_constant_sky() {
    // A constant radiance c projects to L00 = c·2√π and nothing else (Ramamoorthi & Hanrahan 2001).
    let out = dermis(&["sh", "uniform:1,0.5,0.25", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_no_validation_messages(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let l00: Vec<f64> = v["coefficients"]["L00"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let k = 2.0 * std::f64::consts::PI.sqrt();
    for (got, c) in l00.iter().zip([1.0, 0.5, 0.25]) {
        assert!((got - c * k).abs() < 1e-4 * k, "{l00:?}");
    }
    let l22 = v["coefficients"]["L22"][0].as_f64().unwrap();
    assert!(l22.abs() < 1e-4, "{l22}");
    assert_eq!(v["order"][1], "L1-1");
}

/// A lat-long map of 2×1 and 4×2 texels, constant: L00 alone (each texel's
/// basis integrated over its cell; centre samples gave L20 = −3.96, L22 = 6.86).
#[test]
fn sh_of_a_tiny_constant_map_is_l00_alone() {
    for (w, h) in [(2, 1), (4, 2)] {
        let path = tmp(&format!("tiny-{w}x{h}.hdr"));
        let img = image::Rgb32FImage::from_pixel(w, h, image::Rgb([1.0, 1.0, 1.0]));
        img.save(&path).unwrap();
        let out = dermis(&["sh", path.to_str().unwrap(), "--json"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{w}×{h}: {stderr}");
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let k = 2.0 * std::f64::consts::PI.sqrt();
        for (name, c) in v["coefficients"].as_object().unwrap() {
            let want = if name == "L00" { k } else { 0.0 };
            for x in c.as_array().unwrap() {
                let x = x.as_f64().unwrap();
                assert!((x - want).abs() < 1e-4 * k, "{w}×{h}: {name} = {x}");
            }
        }
    }
}

#[test]
fn lights_prints_the_sun_of_the_sky() {
    // The built-in sky's sun: elevation 30°, azimuth 295°; --rotate 90 adds 90° of azimuth.
    let out = dermis(&["lights", "sky", "--rotate", "90", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["mode"], "auto");
    let lights = v["lights"].as_array().unwrap();
    assert_eq!(lights.len(), 1, "{v}");
    let sun = &lights[0];
    let number = |key: &str| sun[key].as_f64().unwrap_or_else(|| panic!("{key}: {sun}"));
    assert!((number("elevation_deg") - 30.0).abs() < 0.5, "{sun}");
    assert!((number("azimuth_deg") - 25.0).abs() < 0.5, "{sun}");
    assert!(number("solid_angle_sr") > 0.0 && number("angular_radius_deg") > 0.0);
    assert!(number("texels") >= 1.0);
    assert_eq!(sun["direction"].as_array().unwrap().len(), 3);
    assert_eq!(sun["power"].as_array().unwrap().len(), 3);
    let (share, residual) = (number("share"), v["residual_share"].as_f64().unwrap());
    assert!((share + residual - 1.0).abs() < 1e-5, "{v}");

    let out = dermis(&["lights", "uniform:1", "--lights", "0"]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("residual: 100.0 %"));
    let out = dermis(&["lights", "/no/such/dir/none.hdr"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("none.hdr"));
    let out = dermis(&["lights", "sky", "--lights", "-1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("got '-1'"));
}

#[test]
fn sh_and_lights_refuse_a_rotation_that_is_not_finite() {
    for command in ["sh", "lights"] {
        for value in ["nan", "inf", "-inf"] {
            let out = dermis(&[command, "uniform:1", "--rotate", value]);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{command} {value}: {stderr}");
            assert!(stderr.contains("--rotate"), "{stderr}");
            assert!(out.stdout.is_empty(), "{command} {value}");
        }
    }
}

/// The binary copied into an empty folder (as `cargo install` or a CI artifact
/// leaves it) and run from there, without the build's checkout to fall back on.
#[test]
fn a_binary_outside_its_checkout_finds_assets_or_says_where_it_looked() {
    let dir = tmp("installed");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("bin")).unwrap();
    let exe = dir.join("bin/dermis");
    std::fs::copy(env!("CARGO_BIN_EXE_dermis"), &exe).unwrap();
    let run = |args: &[&str], assets: Option<&std::path::Path>| {
        let mut c = Command::new(&exe);
        c.args(args)
            .args(["--width", "32", "--height", "32", "--irradiance-res", "256"])
            .arg("--validation")
            .current_dir(&dir)
            .env("DERMIS_NO_BUILD_ASSETS", "1")
            .env_remove("DERMIS_ASSETS");
        if let Some(a) = assets {
            c.env("DERMIS_ASSETS", a);
        }
        c.output().unwrap()
    };
    let out = run(&["render", "--scene", "builtin", "--out", "b.png"], None);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.join("b.png").is_file());

    let out = run(&["render", "--out", "d.png"], None);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for looked in [
        dir.join("assets"),
        dir.join("bin/assets"),
        dir.join("share/dermis/assets"),
    ] {
        assert!(stderr.contains(&looked.display().to_string()), "{stderr}");
    }
    assert!(stderr.contains("DERMIS_ASSETS"), "{stderr}");

    // DERMIS_ASSETS naming no folder: said, not a silent fallback.
    let out = run(
        &["render", "--out", "e.png"],
        Some(std::path::Path::new("/nonexistent/assets")),
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("DERMIS_ASSETS=/nonexistent/assets is not a folder"),
        "{stderr}"
    );

    let json = dir.join("d.json");
    let assets = dermis::assets::dir();
    let out = run(
        &[
            "render",
            "--out",
            "d.png",
            "--report",
            json.to_str().unwrap(),
        ],
        Some(&assets),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(
        report["setup"]["scene"],
        assets.join("default.toml").display().to_string()
    );
}

#[test]
fn precompute_fills_the_cache_and_reports_time() {
    let cache = tmp("cache");
    let run = || {
        Command::new(env!("CARGO_BIN_EXE_dermis"))
            .args(["precompute", "--occlusion", "raytrace", "--validation"])
            .env("DERMIS_CACHE_DIR", &cache)
            .output()
            .unwrap()
    };
    let out = run();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("vertices")
            && stdout.contains(" s (")
            && stdout.contains("specular occlusion (lobe visibility): ")
            && stdout.contains("interreflection: ")
            && stdout.contains("environment transmission: "),
        "{stdout}"
    );
    let files = || std::fs::read_dir(&cache).unwrap().count();
    assert_eq!(
        files(),
        4,
        "the occlusion transfer, the lobe visibility, the interreflected and transmitted transfers"
    );
    assert!(run().status.success(), "second run reads the cache");
    assert_eq!(files(), 4, "and writes nothing new");
    let out = dermis(&["precompute", "--occlusion", "sideways"]);
    assert_eq!(out.status.code(), Some(2));
    // A cache folder that cannot be written: refused before the work.
    let out = Command::new(env!("CARGO_BIN_EXE_dermis"))
        .args(["precompute", "--occlusion", "raytrace"])
        .env("DERMIS_CACHE_DIR", "/proc/dermis-cache")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("/proc/dermis-cache") && stderr.contains("DERMIS_CACHE_DIR"),
        "{stderr}"
    );
    assert!(!stderr.contains("vertices"), "{stderr}");
}

/// `dermis … | head -1`: the reader goes away, dermis finishes its work
/// (every file whole), prints nothing more and exits 0, without a panic.
#[test]
fn a_closed_stdout_is_not_a_panic() {
    let cache = tmp("pipe-cache");
    let _ = std::fs::remove_dir_all(&cache);
    let png = tmp("pipe.png");
    let exe = env!("CARGO_BIN_EXE_dermis");
    for (cmd, files) in [
        (format!("'{exe}' precompute --occlusion raytrace"), 4usize),
        (
            format!(
                "'{exe}' render --timings --dump-graph --width 32 --height 32 \
                 --irradiance-res 256 --out '{}'",
                png.display()
            ),
            0,
        ),
    ] {
        let out = Command::new("bash")
            .arg("-c")
            .arg(format!(
                "{cmd} | head -1; echo \"status ${{PIPESTATUS[0]}}\" >&2"
            ))
            .env("DERMIS_CACHE_DIR", &cache)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("status 0"), "{cmd}: {stderr}");
        assert!(!stderr.contains("panicked"), "{cmd}: {stderr}");
        assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 1);
        if files > 0 {
            assert_eq!(std::fs::read_dir(&cache).unwrap().count(), files);
        }
    }
    assert!(image::open(&png).is_ok());
}

/// Paths that are not UTF-8 are written (and the report's command line
/// carries them lossily), not a panic after the work.
#[test]
fn paths_that_are_not_utf8_are_written() {
    use std::os::unix::ffi::OsStrExt;
    let dir = tmp("non-utf8");
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join(std::ffi::OsStr::from_bytes(b"o\xff.png"));
    let json = dir.join(std::ffi::OsStr::from_bytes(b"r\xff.json"));
    let out = Command::new(env!("CARGO_BIN_EXE_dermis"))
        .args(SMALL_RENDER)
        .arg("--out")
        .arg(&png)
        .arg("--report")
        .arg(&json)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(png.is_file() && json.is_file());
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let line = report["command_line"].to_string();
    assert!(line.contains("o\u{fffd}.png"), "{line}");
}

/// Interrupted (INT, TERM) while a temporary is written: it is removed and
/// the process dies of the signal. Killed outright (KILL), its temporary is
/// removed by the next write into that folder.
#[test]
fn an_interrupted_write_leaves_no_temporary() {
    use std::os::unix::process::ExitStatusExt;
    let names = |d: &std::path::Path| -> Vec<String> {
        let mut n: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        n.sort();
        n
    };
    let render = |dir: &std::path::Path, name: &str, pause: bool| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_dermis"));
        c.args(SMALL_RENDER)
            .arg("--out")
            .arg(dir.join(name))
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null());
        if pause {
            c.env(dermis::atomic::TEST_PAUSE_VAR, "60000");
        }
        c
    };
    // Until the temporary of `x.png` is there (the write is paused on it).
    let wait_for_temporary = |dir: &std::path::Path| {
        let started = std::time::Instant::now();
        while !names(dir).iter().any(|n| n.starts_with(".x.tmp-")) {
            assert!(started.elapsed().as_secs() < 300, "no temporary appeared");
            std::thread::sleep(std::time::Duration::from_millis(50));
        }
    };
    for (signal, number) in [("INT", 2), ("TERM", 15), ("KILL", 9)] {
        let dir = tmp(&format!("interrupted-{signal}"));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let mut child = render(&dir, "x.png", true).spawn().unwrap();
        wait_for_temporary(&dir);
        let killed = Command::new("kill")
            .args(["-s", signal, &child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        let status = child.wait().unwrap();
        assert_eq!(status.signal(), Some(number), "{signal}: {status:?}");
        if signal == "KILL" {
            // Left behind, then swept by the next write into the folder.
            assert_eq!(names(&dir).len(), 1, "{:?}", names(&dir));
            let out = render(&dir, "y.png", false).output().unwrap();
            assert!(out.status.success());
            assert_eq!(names(&dir), ["y.png"]);
        } else {
            assert!(names(&dir).is_empty(), "{signal}: {:?}", names(&dir));
        }
    }
}

#[test]
fn zero_frames_is_a_clean_input_error() {
    assert_bad_input(&["--frames", "0", "--irradiance-res", "256"], "0 frames");
    assert_bad_input(&["--runs", "0", "--irradiance-res", "256"], "0 runs");
    assert_bad_input(
        &["--frames", "3", "--warmup", "3", "--irradiance-res", "256"],
        "--warmup 3 leaves none of --frames 3 measured",
    );
}

#[test]
fn help_documents_every_flag_the_environment_and_exit_codes() {
    for command in ["info", "sh", "lights", "precompute", "render"] {
        let out = dermis(&[command, "--help"]);
        assert!(out.status.success(), "{command} --help");
        let help = String::from_utf8_lossy(&out.stdout).to_string();
        let lines: Vec<&str> = help.lines().collect();
        let mut flags = 0;
        for (i, line) in lines.iter().enumerate() {
            let t = line.trim_start();
            if !(t.starts_with("--")
                || (t.starts_with('-') && t.chars().nth(1).is_some_and(char::is_alphabetic)))
            {
                continue;
            }
            flags += 1;
            // Short help puts the description on the flag's line after two spaces,
            // long help on the lines after it.
            let doc = match t.split_once("  ") {
                Some((_, rest)) if !rest.trim().is_empty() => rest.trim(),
                _ => lines.get(i + 1).map_or("", |l| l.trim()),
            };
            assert!(!doc.is_empty(), "{command}: {t:?} has no help text\n{help}");
        }
        assert!(flags >= 4, "{command}: only {flags} flags found\n{help}");
        for needle in [
            "DERMIS_DEVICE",
            "DERMIS_VALIDATION",
            "DERMIS_CACHE_DIR",
            "RUST_LOG",
            "Exit status",
            "2 bad input",
        ] {
            assert!(help.contains(needle), "{command} --help lacks {needle}");
        }
    }
    // Value lists come from the enums.
    let help = String::from_utf8_lossy(&dermis(&["render", "--help"]).stdout).to_string();
    for value in [
        "blur6",
        "stretch5",
        "test-texture",
        "regions",
        "neutral",
        "--debug-sheet",
        "--compare-occlusion",
        "--blur-width",
        "--blur-amount",
        "--glow-intensity",
        "--background",
        "prefiltered",
        "raytrace",
        "bottom-left",
        "--env-lights",
    ] {
        assert!(help.contains(value), "render --help lacks {value}");
    }
}

#[test]
fn view_list_prints_every_view() {
    let out = dermis(&[
        "render",
        "--view",
        "list",
        "--irradiance-res",
        "256",
        "--width",
        "64",
        "--height",
        "80",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let listed = String::from_utf8_lossy(&out.stdout);
    let names: Vec<&str> = listed.lines().collect();
    for name in [
        "final",
        "depth",
        "test-texture",
        "irradiance",
        "stretch",
        "stretch5",
    ] {
        assert!(names.contains(&name), "{name} not in {names:?}");
    }
    for name in ["blur1", "blur6", "prefiltered"] {
        assert!(names.contains(&name), "{name} not in {names:?}");
    }
}

/// A validation message fails the run (exit status 4) and is counted in the
/// report; the message is injected through the layer's own messenger
/// (`DERMIS_TEST_VALIDATION_MESSAGE`, test-only).
#[test]
fn a_validation_message_fails_the_run() {
    let json = tmp("validation-report.json");
    let run = |message: Option<&str>| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_dermis"));
        c.args([
            "render", "--scene", "builtin", "--width", "32", "--height", "32",
        ])
        .args(["--irradiance-res", "256", "--validation", "--report"])
        .arg(&json)
        .arg("--out")
        .arg(tmp("validation.png"));
        if let Some(m) = message {
            c.env("DERMIS_TEST_VALIDATION_MESSAGE", m);
        }
        let out = c.output().unwrap();
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        (out, report["validation_messages"].clone())
    };
    let (out, count) = run(None);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(count, 0);
    let (out, count) = run(Some("deliberate test message"));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(4), "{stderr}");
    assert!(stderr.contains("deliberate test message"), "{stderr}");
    assert!(
        stderr.contains("validation layer reported 1 message"),
        "{stderr}"
    );
    assert_eq!(count, 1);
}

/// The CPU reference says how far it is (plain lines: stderr is no terminal)
/// and how well it converged.
#[test]
fn the_cpu_reference_reports_progress_and_convergence() {
    let png = tmp("reference.png");
    let out = dermis(&[
        "render",
        "--scene",
        "builtin",
        "--view",
        "reference",
        "--width",
        "24",
        "--height",
        "20",
        "--out",
        png.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    for line in [
        "reference: started",
        "reference: 50 % (10/20)",
        "left",
        "reference: done in",
    ] {
        assert!(stderr.contains(line), "{line}: {stderr}");
    }
    assert!(stderr.contains("converged to 0.5 %"), "{stderr}");
}

#[test]
fn reference_diffusion_refuses_bad_input() {
    for (args, needle) in [
        (&["--stride", "0"][..], "--stride"),
        (&["--blur-width", "0"][..], "skin.blur_width"),
    ] {
        let out = dermis(
            &[
                &["reference", "--diffusion", "--irradiance-res", "256"],
                args,
            ]
            .concat(),
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(
            stderr
                .lines()
                .any(|l| l.starts_with("error:") && l.contains(needle)),
            "{stderr}"
        );
    }
}

/// The pre-roll: frames rendered after the first for --warmup-ms and left out of
/// the report; none by default on a CPU device (lavapipe).
#[test]
fn render_preroll_frames_are_rendered_but_not_reported() {
    let frames_of = |extra: &[&str]| {
        let json = tmp(&format!("preroll{}.json", extra.len()));
        let png = tmp(&format!("preroll{}.png", extra.len()));
        let mut args = vec![
            "render",
            "--out",
            png.to_str().unwrap(),
            "--irradiance-res",
            "256",
            "--width",
            "64",
            "--height",
            "48",
            "--frames",
            "3",
            "--report",
            json.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let out = dermis(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_no_validation_messages(&out);
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        assert_eq!(report["frames"], 3);
        let numbers: Vec<u64> = report["per_frame"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f["frame"].as_u64().unwrap())
            .collect();
        (report["preroll_ms"].as_u64().unwrap(), numbers)
    };
    assert_eq!(
        frames_of(&[]),
        (0, vec![0, 1, 2]),
        "no pre-roll on lavapipe"
    );
    let (ms, numbers) = frames_of(&["--warmup-ms", "300"]);
    assert_eq!(ms, 300);
    assert_eq!(numbers.len(), 3);
    assert_eq!(numbers[0], 0, "the first frame is reported");
    assert!(numbers[1] > 1, "pre-roll frames come between: {numbers:?}");
    assert_eq!(numbers[2], numbers[1] + 1);
}

/// `dermis medium`: deon2007 prints the Gaussians' T(d) at the thicknesses
/// asked, matching the CPU profile; bad thicknesses and media are refused with
/// exit 2, naming the flag or key, before any walk.
#[test]
fn medium_prints_the_profiles_transmission_and_refuses_bad_input() {
    let out = dermis(&["medium", "--medium", "deon2007", "--thickness", "1", "2"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let p = dermis::skin::profile::Profile::skin();
    for d in [1.0f32, 2.0] {
        let t = p.transmittance(d);
        let line = format!(
            "T({d} mm) = Σ wᵢ exp(−d²/2vᵢ) = {:.4} {:.4} {:.4}",
            t.x, t.y, t.z
        );
        assert!(text.contains(&line), "{line:?} not in {text}");
    }
    let out = dermis(&["medium", "--thickness", "0"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--thickness"));
    let out = dermis(&["medium", "--medium", "jensen-skin9"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--medium"));
}
