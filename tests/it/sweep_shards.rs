//! Sharded sweeps as users run them, with validation on: three shard processes
//! and a merge give the unsharded sweep point for point (errors bit for bit:
//! rendering is deterministic on one device); `--list-points`, `--shard auto`,
//! bad shards, `--resume`.

use serde_json::Value;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};

/// Variables that would shard a run behind the test's back.
const SHARD_ENV: &[&str] = &[
    "DERMIS_SHARD",
    "DERMIS_SHARD_TOTAL",
    "SLURM_ARRAY_TASK_ID",
    "SLURM_ARRAY_TASK_MIN",
    "SLURM_ARRAY_TASK_MAX",
    "SLURM_ARRAY_TASK_STEP",
    "SLURM_ARRAY_TASK_COUNT",
    "JOB_COMPLETION_INDEX",
    "CI_NODE_INDEX",
    "CI_NODE_TOTAL",
    "TEST_SHARD_INDEX",
    "TEST_TOTAL_SHARDS",
    "TEST_SHARD_STATUS_FILE",
];

fn command<S: AsRef<OsStr>>(args: &[S], env: &[(&str, &str)]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_dermis"));
    c.args(args).arg("--validation");
    for k in SHARD_ENV {
        c.env_remove(k);
    }
    c.envs(env.iter().copied());
    c
}

fn spawn<S: AsRef<OsStr>>(args: &[S]) -> Child {
    command(args, &[])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("dermis runs")
}

fn dermis<S: AsRef<OsStr>>(args: &[S], env: &[(&str, &str)]) -> Output {
    command(args, env).output().expect("dermis runs")
}

/// Succeeded without a validation message.
fn check(what: &str, out: &Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{what}: {stderr}");
    assert!(
        !stderr.contains("[validation]"),
        "{what}: validation messages:\n{stderr}"
    );
    stderr
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("dermis-shards-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn lines(path: &Path) -> Vec<Value> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// Two points (one of them the reference's own settings, at zero error).
const SWEEP: &[&str] = &[
    "sweep",
    "--scene",
    "builtin",
    "--resolutions",
    "256",
    "--kernels",
    "deon7,accurate",
    "--chains",
    "full",
    "--reference-resolution",
    "256",
    "--width",
    "64",
    "--height",
    "80",
    "--frames",
    "2",
];

fn with(extra: &[&str]) -> Vec<String> {
    SWEEP.iter().chain(extra).map(|s| s.to_string()).collect()
}

fn ids(sweep: &Value) -> Vec<String> {
    sweep["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["id"].as_str().unwrap().to_string())
        .collect()
}

#[test]
fn three_shards_merge_into_the_unsharded_sweep() {
    let (whole, shards, merged) = (tmp("whole"), tmp("shards"), tmp("merged"));
    let started = std::time::Instant::now();
    // The unsharded sweep and three shard processes, all at once.
    let mut children = vec![(
        "unsharded".to_string(),
        spawn(&with(&["--out-dir", whole.to_str().unwrap()])),
    )];
    for i in 1..=3 {
        let shard = format!("{i}/3");
        children.push((
            format!("shard {shard}"),
            spawn(&with(&[
                "--shard",
                &shard,
                "--out-dir",
                shards.to_str().unwrap(),
            ])),
        ));
    }
    for (what, child) in children {
        let out = child.wait_with_output().unwrap();
        let stderr = check(&what, &out);
        if let Some(shard) = what.strip_prefix("shard ") {
            assert!(
                stderr.contains(&format!("shard {shard} by id hash (from --shard)")),
                "{what}: {stderr}"
            );
        }
    }
    println!("4 processes: {:.1} s", started.elapsed().as_secs_f64());

    let unsharded = json(&whole.join("sweep.json"));
    assert_eq!(ids(&unsharded), ["r256-deon7-full", "r256-accurate-full"]);
    let hash = unsharded["sweep_hash"].as_str().unwrap();
    assert_eq!(hash.len(), 16);
    assert_eq!(unsharded["schema_version"], 1);
    assert!(unsharded["fingerprint"]["device"].as_str().is_some());
    assert!(!unsharded["run_id"].as_str().unwrap().is_empty());
    // The unsharded log: its header and both points.
    let log = lines(&whole.join("points.jsonl"));
    assert_eq!(log.len(), 3);
    assert_eq!(log[0]["record"], "header");
    assert_eq!(log[0]["shard"], "all");
    assert_eq!(log[0]["sweep_hash"], hash);

    // Each shard's log: a header (an empty shard's too), then its points.
    let mut total = 0;
    let mut checksums = Vec::new();
    for i in 1..=3 {
        let path = shards.join(format!("points-shard-{i}-of-3.jsonl"));
        let log = lines(&path);
        let header = &log[0];
        assert_eq!(header["record"], "header", "{}", path.display());
        assert_eq!(header["shard"], format!("hash:{i}/3"));
        assert_eq!(header["sweep_hash"], hash);
        let points = header["shard_points"].as_array().unwrap();
        assert_eq!(log.len(), 1 + points.len(), "{}", path.display());
        for (p, id) in log[1..].iter().zip(points) {
            assert_eq!(p["record"], "point");
            assert_eq!(&p["id"], id);
            let samples = p["passes"][0]["samples_ns"].as_array().unwrap();
            assert_eq!(samples.len(), 1, "one measured frame of two");
        }
        total += points.len();
        checksums.push(header["reference_checksum"].clone());
    }
    assert_eq!(total, 2);
    assert!(checksums
        .iter()
        .all(|c| *c == unsharded["reference_checksum"]));

    // --list-points --json: the same ids and hash, nothing rendered.
    let out = dermis(&with(&["--list-points", "--json"]), &[]);
    check("--list-points", &out);
    let list: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(list["sweep_hash"], hash);
    assert_eq!(ids(&list), ids(&unsharded));

    // The merge: same points in the same order, errors bit for bit.
    let out = dermis(
        &[
            "sweep",
            "merge",
            shards.to_str().unwrap(),
            "--out-dir",
            merged.to_str().unwrap(),
        ],
        &[],
    );
    let stderr = check("merge", &out);
    assert!(!stderr.contains("warning"), "{stderr}");
    let m = json(&merged.join("sweep.json"));
    assert_eq!(ids(&m), ids(&unsharded));
    for key in [
        "sweep_hash",
        "reference_checksum",
        "reference",
        "scene",
        "width",
        "frames",
    ] {
        assert_eq!(m[key], unsharded[key], "{key}");
    }
    for (a, b) in m["points"]
        .as_array()
        .unwrap()
        .iter()
        .zip(unsharded["points"].as_array().unwrap())
    {
        for key in [
            "final_error",
            "diffuse_error",
            "resolution",
            "kernel",
            "chain",
        ] {
            assert_eq!(a[key], b[key], "{}: {key}", a["id"]);
        }
        let names = |p: &Value| -> Vec<Value> {
            p["passes"]
                .as_array()
                .unwrap()
                .iter()
                .map(|s| s["name"].clone())
                .collect()
        };
        assert_eq!(names(a), names(b));
        assert!(a["total_ms"].as_f64().unwrap() > 0.0);
    }
    assert_eq!(m["shards"].as_array().unwrap().len(), 3);
    for f in [
        "sweep.csv",
        "time_vs_error.svg",
        "time_vs_error.png",
        "passes.png",
    ] {
        assert!(merged.join(f).is_file(), "merge wrote no {f}");
    }
    let csv = std::fs::read_to_string(merged.join("sweep.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(header.ends_with("point_id,run_id,sweep_hash,scene,environment,device,git_commit"));
    assert!(csv.lines().skip(1).all(|l| l.contains(hash)));

    // The merged sweep compared with the unsharded one, point by point: same
    // setup, no point missing; the JUnit file has a suite per point.
    let junit = merged.join("compare.xml");
    let out = dermis(
        &[
            "compare",
            whole.join("sweep.json").to_str().unwrap(),
            merged.join("sweep.json").to_str().unwrap(),
            "--json",
            "--junit",
            junit.to_str().unwrap(),
        ],
        &[],
    );
    check("compare", &out);
    let c: Value = serde_json::from_slice(&out.stdout).unwrap();
    let compared: Vec<&str> = c["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["id"].as_str().unwrap())
        .collect();
    assert_eq!(compared, ids(&unsharded), "{c}");
    for p in c["points"].as_array().unwrap() {
        let passes = p["comparison"]["passes"].as_array().unwrap();
        assert!(passes.iter().any(|r| r["name"] == "skin"), "{p}");
        assert!(passes.iter().all(|r| r["sample"] == "frame"), "{p}");
    }
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert_eq!(xml.matches("<testsuite ").count(), compared.len(), "{xml}");

    // A shard's log missing: the merge names the points it lacks.
    let holder = (1..=3)
        .map(|i| shards.join(format!("points-shard-{i}-of-3.jsonl")))
        .find(|p| lines(p).len() > 1)
        .unwrap();
    std::fs::remove_file(&holder).unwrap();
    let out = dermis(&["sweep", "merge", shards.to_str().unwrap()], &[]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("missing") && stderr.contains("r256-"),
        "{stderr}"
    );

    // A killed sweep resumed: the log cut inside its last point; --resume
    // renders only that point and gives the same sweep.
    let log = std::fs::read_to_string(whole.join("points.jsonl")).unwrap();
    let cut = log.trim_end().rfind('\n').unwrap() + 40;
    std::fs::write(whole.join("points.jsonl"), &log[..cut]).unwrap();
    std::fs::remove_file(whole.join("sweep.json")).unwrap();
    let out = dermis(
        &with(&["--resume", "--out-dir", whole.to_str().unwrap()]),
        &[],
    );
    check("--resume", &out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        stdout
            .lines()
            .filter(|l| l.trim_start().starts_with("256 "))
            .count(),
        1,
        "--resume rendered more than the lost point:\n{stdout}"
    );
    let resumed = json(&whole.join("sweep.json"));
    assert_eq!(ids(&resumed), ids(&unsharded));
    for (a, b) in resumed["points"]
        .as_array()
        .unwrap()
        .iter()
        .zip(unsharded["points"].as_array().unwrap())
    {
        assert_eq!(a["final_error"], b["final_error"]);
    }
    let log = lines(&whole.join("points.jsonl"));
    let records: Vec<&str> = log.iter().map(|l| l["record"].as_str().unwrap()).collect();
    assert_eq!(records, ["header", "point", "header", "point"]);
}

#[test]
fn shard_auto_reads_the_scheduler_and_bad_shards_exit_2() {
    let slurm = [
        ("SLURM_ARRAY_TASK_ID", "3"),
        ("SLURM_ARRAY_TASK_MIN", "1"),
        ("SLURM_ARRAY_TASK_STEP", "1"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
    ];
    let out = dermis(
        &with(&["--shard", "count:auto", "--list-points", "--json"]),
        &slurm,
    );
    let stderr = check("--shard auto", &out);
    assert!(
        stderr.contains("shard 3/3 by position (from SLURM_ARRAY_TASK_ID=3)"),
        "{stderr}"
    );
    let list: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(list["shard"], "count:3/3");
    assert_eq!(
        ids(&list),
        Vec::<String>::new(),
        "two points, the third shard by position is empty"
    );
    // DERMIS_SHARD without --shard; an explicit --shard wins over it.
    let out = dermis(
        &with(&["--list-points", "--json"]),
        &[("DERMIS_SHARD", "count:2/2")],
    );
    check("DERMIS_SHARD", &out);
    let list: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(ids(&list), ["r256-accurate-full"]);
    let out = dermis(
        &with(&["--shard", "count:1/2", "--list-points", "--json"]),
        &[("DERMIS_SHARD", "count:2/2")],
    );
    let list: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(ids(&list), ["r256-deon7-full"]);

    // An irregular list (--array=1,4,9) is refused before any work, saying why.
    let irregular = [
        ("SLURM_ARRAY_TASK_ID", "4"),
        ("SLURM_ARRAY_TASK_MIN", "1"),
        ("SLURM_ARRAY_TASK_MAX", "9"),
        ("SLURM_ARRAY_TASK_STEP", "1"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
    ];
    let out = dermis(
        &with(&["--shard", "auto", "--out-dir", "/nonexistent/x"]),
        &irregular,
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("not a regular range") && stderr.contains("MAX=9"),
        "{stderr}"
    );
    assert!(!Path::new("/nonexistent/x").exists());

    for bad in ["0/3", "4/3", "x/y", "1/0", "auto"] {
        let out = dermis(&with(&["--shard", bad, "--out-dir", "/nonexistent/x"]), &[]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "--shard {bad}: {stderr}");
        assert!(stderr.contains("--shard"), "--shard {bad}: {stderr}");
    }
    let out = dermis(&["sweep", "merge", "/nonexistent/shards"], &[]);
    assert_eq!(out.status.code(), Some(2));
}

/// docs/recipes/slurm-sweep.sh with `sbatch` and `sinfo` stubbed (no Slurm
/// here): the launcher sizes the tasks to the smallest node, makes the merge
/// cancellable, retries one shard with --resume; the task part gives dermis
/// its shard of SHARDS even when the array is that one index.
#[test]
fn the_slurm_recipe_submits_and_retries_shards() {
    let dir = tmp("slurm-recipe");
    let bin = dir.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let calls = dir.join("sbatch-calls");
    let stub = |name: &str, body: &str| {
        let path = bin.join(name);
        std::fs::write(&path, format!("#!/bin/bash\n{body}\n")).unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    };
    // --test-only as Slurm 22.05 answers it on a 2-CPU node.
    stub(
        "sbatch",
        &format!(
            "case \"$*\" in *--test-only*--cpus-per-task=[12]\\ *) exit 0 ;;\n\
             *--test-only*) echo 'allocation failure: Requested node configuration is not \
             available' >&2; exit 1 ;; esac\n\
             echo \"$* | SWEEP_ARGS=$SWEEP_ARGS\" >> '{}'; echo 4242",
            calls.display()
        ),
    );
    stub("sinfo", "printf '2\\n16\\n'");
    let recipe = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/recipes/slurm-sweep.sh");
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let launch_with = |args: &[&str], env: &[(&str, &str)]| {
        let mut c = Command::new("bash");
        c.arg(&recipe).args(args).env("PATH", &path);
        for k in SHARD_ENV
            .iter()
            .chain(&["CPUS", "SHARDS", "SWEEP_ARGS", "OUT", "SBATCH_ARGS"])
        {
            c.env_remove(k);
        }
        c.envs(env.iter().copied());
        c.env("OUT", dir.join("out")).output().unwrap()
    };
    let launch = |args: &[&str]| launch_with(args, &[]);
    let out = launch(&[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = launch(&["2"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("shards 2 of 3"));
    let bad = launch(&["4"]);
    assert_eq!(bad.status.code(), Some(2));
    // More CPUs than any node: refused before submitting (Slurm would leave
    // the tasks PENDING (PartitionConfig) for ever), saying what to set.
    let big = launch_with(&[], &[("CPUS", "8")]);
    let stderr = String::from_utf8_lossy(&big.stderr);
    assert_eq!(big.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("8 CPUs")
            && stderr.contains("Requested node configuration is not available")
            && stderr.contains("set CPUS"),
        "{stderr}"
    );
    let text = std::fs::read_to_string(&calls).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 4, "{text}");
    // The array: all shards, sized to the 2-CPU node; the merge after it.
    assert!(
        lines[0].contains("--array=1-3")
            && lines[0].contains("--cpus-per-task=2")
            && !lines[0].contains("--resume"),
        "{}",
        lines[0]
    );
    assert!(
        lines[1].contains("--dependency=afterok:4242")
            && lines[1].contains("--kill-on-invalid-dep=yes")
            && lines[1].contains("sweep merge"),
        "{}",
        lines[1]
    );
    // The retry: shard 2 alone, resumed, and a merge of its own.
    assert!(
        lines[2].contains("--array=2 ") && lines[2].contains("SWEEP_ARGS=--frames 4 --resume"),
        "{}",
        lines[2]
    );
    assert!(
        lines[3].contains("--kill-on-invalid-dep=yes"),
        "{}",
        lines[3]
    );

    // The retried task as Slurm runs it (--array=2: MIN = MAX = 2, COUNT 1).
    let args = with(&["--list-points", "--json"])[1..].join(" ");
    let out = Command::new("bash")
        .arg(&recipe)
        .env("DERMIS", env!("CARGO_BIN_EXE_dermis"))
        .env("OUT", dir.join("out"))
        .env("SWEEP_ARGS", &args)
        .env_remove("DERMIS_SHARD")
        .env_remove("DERMIS_SHARD_TOTAL")
        .env_remove("SHARDS")
        .envs([
            ("SLURM_ARRAY_TASK_ID", "2"),
            ("SLURM_ARRAY_TASK_MIN", "2"),
            ("SLURM_ARRAY_TASK_MAX", "2"),
            ("SLURM_ARRAY_TASK_STEP", "1"),
            ("SLURM_ARRAY_TASK_COUNT", "1"),
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("shard 2/3 by id hash"), "{stderr}");
    let list: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(list["shard"], "hash:2/3");

    // `sbatch --array=1,4,9` of the recipe itself (SHARDS 3): task 1 refuses
    // too, before any work, so no shard of it renders.
    let out = Command::new("bash")
        .arg(&recipe)
        .env("DERMIS", env!("CARGO_BIN_EXE_dermis"))
        .env("OUT", dir.join("irregular"))
        .env("SWEEP_ARGS", with(&[])[1..].join(" "))
        .env_remove("DERMIS_SHARD")
        .env_remove("DERMIS_SHARD_TOTAL")
        .env_remove("SHARDS")
        .envs([
            ("SLURM_ARRAY_TASK_ID", "1"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
            ("SLURM_ARRAY_TASK_MAX", "9"),
            ("SLURM_ARRAY_TASK_STEP", "1"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("MIN=1 to MAX=9"), "{stderr}");
    let written: Vec<_> = std::fs::read_dir(dir.join("irregular")).unwrap().collect();
    assert!(written.is_empty(), "{written:?}");
}

/// Two sweeps into one --out-dir at once: the second is refused before any
/// work (the first holds its log's lock), the first's log stays whole. The
/// folder's name is not UTF-8 (a panic once, after the work).
#[test]
fn a_second_sweep_into_one_folder_is_refused() {
    use std::os::unix::ffi::OsStrExt;
    let out_dir = tmp("concurrent").join(OsStr::from_bytes(b"sw\xff"));
    let mut args: Vec<std::ffi::OsString> =
        with(&["--out-dir"]).into_iter().map(Into::into).collect();
    args.push(out_dir.clone().into());
    let first = spawn(&args);
    let log = out_dir.join("points.jsonl");
    let started = std::time::Instant::now();
    while !log.exists() {
        assert!(
            started.elapsed().as_secs() < 300,
            "the first sweep never started"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let second = dermis(&args, &[]);
    let stderr = String::from_utf8_lossy(&second.stderr);
    assert_eq!(second.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("another dermis sweep"), "{stderr}");
    let first = first.wait_with_output().unwrap();
    check("the first sweep", &first);
    let records: Vec<String> = lines(&log)
        .iter()
        .map(|l| l["record"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(records, ["header", "point", "point"]);
    assert!(out_dir.join("sweep.json").is_file());
}

/// docs/recipes/k8s-sweep-job.yaml and github-sweep.yml as their schedulers
/// would run them (neither runs here: no cluster, no GitHub; see
/// docs/records/2026-11-29-slurm-recipe.md): the Job's command with each
/// JOB_COMPLETION_INDEX, the workflow's --shard expression with each matrix
/// job's strategy.job-index, give shards 1..N of N that cover the sweep once.
#[test]
fn the_k8s_and_github_recipes_shard_as_documented() {
    let recipes = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/recipes");
    let read = |name: &str| {
        std::fs::read_to_string(recipes.join(name))
            .unwrap_or_else(|e| panic!("docs/recipes/{name}: {e}"))
    };
    let line_after = |text: &str, key: &str| -> String {
        let line = text
            .lines()
            .find(|l| l.contains(key))
            .unwrap_or_else(|| panic!("no line with {key:?}"));
        line[line.find(key).unwrap() + key.len()..]
            .trim()
            .to_string()
    };
    // The tiny sweep's options, less --frames (the recipes give their own).
    let frames = SWEEP.iter().position(|a| *a == "--frames").unwrap();
    let tiny: Vec<String> = with(&["--list-points", "--json"])
        .into_iter()
        .enumerate()
        .filter(|&(i, _)| i != 0 && i != frames && i != frames + 1)
        .map(|(_, a)| a)
        .collect();
    let all = ids(&serde_json::from_slice(
        &dermis(&with(&["--list-points", "--json"]), &[]).stdout,
    )
    .unwrap());
    assert_eq!(all.len(), 2);
    let covers = |shards: Vec<Value>, n: usize, what: &str| {
        let mut seen: Vec<String> = Vec::new();
        for (i, list) in shards.iter().enumerate() {
            assert_eq!(list["shard"], format!("hash:{}/{n}", i + 1), "{what}");
            seen.extend(ids(list));
        }
        seen.sort();
        let mut want = all.clone();
        want.sort();
        assert_eq!(seen, want, "{what}: every point in exactly one shard");
    };

    // Kubernetes: completions = DERMIS_SHARD_TOTAL; the pod's command as given.
    let k8s = read("k8s-sweep-job.yaml");
    let n: usize = line_after(&k8s, "completions:").parse().unwrap();
    let total_line = k8s
        .lines()
        .skip_while(|l| !l.contains("- name: DERMIS_SHARD_TOTAL"))
        .nth(1)
        .unwrap();
    assert!(
        total_line.contains(&format!("value: \"{n}\"")),
        "DERMIS_SHARD_TOTAL must equal completions ({n}): {total_line}"
    );
    let command: Vec<String> = serde_json::from_str(&line_after(&k8s, "command: ")).unwrap();
    assert_eq!(command[..4], ["dermis", "sweep", "--shard", "auto"]);
    let out_dir = tmp("k8s");
    let pods: Vec<Value> = (0..n)
        .map(|index| {
            let mut args: Vec<String> = command[1..]
                .iter()
                .map(|a| {
                    if a == "/results" {
                        out_dir.display().to_string()
                    } else {
                        a.clone()
                    }
                })
                .collect();
            args.extend(tiny.iter().cloned());
            let out = dermis(
                &args,
                &[
                    ("JOB_COMPLETION_INDEX", &index.to_string()),
                    ("DERMIS_SHARD_TOTAL", &n.to_string()),
                ],
            );
            let stderr = check(&format!("pod {index}"), &out);
            assert!(
                stderr.contains(&format!("(from JOB_COMPLETION_INDEX={index})")),
                "{stderr}"
            );
            serde_json::from_slice(&out.stdout).unwrap()
        })
        .collect();
    covers(pods, n, "k8s-sweep-job.yaml");

    // GitHub: the matrix's entries are the jobs; bash evaluates the --shard
    // expression once GitHub has substituted ${{ … }}.
    let gh = read("github-sweep.yml");
    let matrix = line_after(&gh, "shard: [");
    let n = matrix[..matrix.find(']').unwrap()].split(',').count();
    let expression = line_after(&gh, "--shard $((");
    let expression = format!("$(({}", expression.trim_end_matches('\\').trim());
    let jobs: Vec<Value> = (0..n)
        .map(|index| {
            let script = expression
                .replace("${{ strategy.job-index }}", &index.to_string())
                .replace("${{ strategy.job-total }}", &n.to_string());
            let shard = Command::new("bash")
                .args(["-c", &format!("echo {script}")])
                .output()
                .unwrap();
            let shard = String::from_utf8(shard.stdout).unwrap().trim().to_string();
            assert_eq!(shard, format!("{}/{n}", index + 1), "{expression}");
            let mut args = vec!["--shard".to_string(), shard];
            args.extend(tiny.iter().cloned());
            let mut full = vec!["sweep".to_string()];
            full.extend(args);
            let out = dermis(&full, &[]);
            check(&format!("matrix job {index}"), &out);
            serde_json::from_slice(&out.stdout).unwrap()
        })
        .collect();
    covers(jobs, n, "github-sweep.yml");
}
