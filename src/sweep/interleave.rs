//! `dermis interleave`: two binaries or two option sets run as alternating
//! processes (A B, then B A: a drift of the machine falls on both sides alike),
//! each a `render --frames F --ruler --report`, read back as two measurements
//! for `dermis compare`.

use crate::error::{Error, Result};
use crate::timing::regression::Measurement;
use std::path::{Path, PathBuf};

/// Options `interleave` sets itself on each run.
pub const OWNS: [&str; 5] = ["--report", "--out", "--frames", "--runs", "--ruler"];

/// Runs each side `runs` times as separate processes, alternating A B B A …,
/// and reads their reports back, pooled per side.
pub fn run(
    sides: &[(&str, PathBuf, String); 2],
    runs: u32,
    frames: u32,
    out_dir: &Path,
) -> Result<[(Measurement, Vec<String>); 2]> {
    if runs < 2 || frames < 2 {
        return Err(Error::Input(format!(
            "interleave: --runs {runs} --frames {frames}: give at least 2 of each \
             (runs are the samples; each run's first frame is warm-up)"
        )));
    }
    let mut args = Vec::new();
    for (name, bin, text) in sides {
        let a = shlex::split(text)
            .ok_or_else(|| Error::Input(format!("--{name}-args {text:?}: unbalanced quotes")))?;
        if let Some(owned) = a
            .iter()
            .find(|x| OWNS.iter().any(|o| x.split('=').next() == Some(o)))
        {
            return Err(Error::Input(format!(
                "--{name}-args: {owned} is set by interleave itself ({})",
                OWNS.join(", ")
            )));
        }
        if !bin.is_file() {
            return Err(Error::Input(format!(
                "--{name}-bin {}: no such file",
                bin.display()
            )));
        }
        args.push(a);
    }
    for (name, _, _) in sides {
        let dir = out_dir.join(name);
        std::fs::create_dir_all(&dir).map_err(|source| Error::Io {
            path: dir.display().to_string(),
            source,
        })?;
    }
    let mut files: [Vec<PathBuf>; 2] = [Vec::new(), Vec::new()];
    for k in 0..runs {
        // A B, then B A: a linear drift falls on both sides alike.
        let order = if k % 2 == 0 { [0, 1] } else { [1, 0] };
        for i in order {
            let (name, bin, _) = &sides[i];
            let report = out_dir.join(name).join(format!("run-{k:03}.json"));
            let started = std::time::Instant::now();
            let status = std::process::Command::new(bin)
                .arg("render")
                .args(&args[i])
                .args(["--frames", &frames.to_string(), "--ruler", "--report"])
                .arg(&report)
                .arg("--out")
                .arg(out_dir.join(format!("{name}.png")))
                .stdout(std::process::Stdio::null())
                .status()
                .map_err(|source| Error::Io {
                    path: bin.display().to_string(),
                    source,
                })?;
            if !status.success() {
                return Err(Error::Input(format!(
                    "interleave: {name} run {} of {runs} ({} render …) failed: {status}",
                    k + 1,
                    bin.display()
                )));
            }
            eprintln!(
                "{name} {}/{runs}: {:.1} s",
                k + 1,
                started.elapsed().as_secs_f64()
            );
            files[i].push(report);
        }
    }
    let pool = |f: &[PathBuf]| -> Result<(Measurement, Vec<String>)> {
        let (mut m, w) = super::side::pool(f)?;
        m.source = format!("{} × {}", f.len(), f[0].display());
        Ok((m, w))
    };
    Ok([pool(&files[0])?, pool(&files[1])?])
}
