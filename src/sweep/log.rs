//! The points log: JSON Lines, one record per line, each an object whose
//! `record` says what it is. A run writes a `header` first, then one `point`
//! per completed point, each appended and flushed (and synced) as it completes,
//! so a killed sweep loses at most the point in progress. A resumed run appends
//! a second header and its points to the same file.

use super::shard::Shard;
use super::{Point, Sweep, Variant};
use crate::error::{Error, Result};
use crate::timing::Fingerprint;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The first line of a run.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Header {
    /// Always "header".
    pub record: String,
    pub schema_version: u32,
    pub sweep_hash: String,
    /// `hash:2/3`, `count:1/4`, or `all` (unsharded).
    pub shard: String,
    /// This shard's point ids, canonical order.
    pub shard_points: Vec<String>,
    /// Every point id of the sweep, canonical order (what `merge` expects).
    pub sweep_points: Vec<String>,
    pub run_id: String,
    /// UTC, RFC 3339 to the second.
    pub timestamp: String,
    pub dermis_version: String,
    pub git_commit: String,
    pub fingerprint: Fingerprint,
    /// FNV-1a 64 of this run's reference final and diffuse images.
    pub reference_checksum: String,
    pub reference: Variant,
    pub scene: String,
    pub environment: String,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
}

impl Header {
    pub fn new(sweep: &Sweep, shard: Option<Shard>, all: &[String], mine: &[Variant]) -> Self {
        Self {
            record: "header".into(),
            schema_version: sweep.schema_version,
            sweep_hash: sweep.sweep_hash.clone(),
            shard: shard.map_or_else(|| "all".into(), |s| s.to_string()),
            shard_points: mine.iter().map(Variant::id).collect(),
            sweep_points: all.to_vec(),
            run_id: sweep.run_id.clone(),
            timestamp: sweep.timestamp.clone(),
            dermis_version: sweep.dermis_version.clone(),
            git_commit: sweep.git_commit.clone(),
            fingerprint: sweep.fingerprint.clone(),
            reference_checksum: sweep.reference_checksum.clone(),
            reference: sweep.reference,
            scene: sweep.scene.clone(),
            environment: sweep.environment.clone(),
            width: sweep.width,
            height: sweep.height,
            frames: sweep.frames,
        }
    }

    /// The sweep this header describes, without points.
    pub fn sweep(&self) -> Sweep {
        Sweep {
            schema_version: self.schema_version,
            sweep_hash: self.sweep_hash.clone(),
            run_id: self.run_id.clone(),
            timestamp: self.timestamp.clone(),
            dermis_version: self.dermis_version.clone(),
            git_commit: self.git_commit.clone(),
            device: self.fingerprint.device.clone(),
            driver: self.fingerprint.driver.clone(),
            fingerprint: self.fingerprint.clone(),
            scene: self.scene.clone(),
            environment: self.environment.clone(),
            width: self.width,
            height: self.height,
            frames: self.frames,
            reference: self.reference,
            reference_checksum: self.reference_checksum.clone(),
            points: Vec::new(),
            shards: Vec::new(),
        }
    }
}

#[derive(Serialize)]
struct PointRecord<'a> {
    record: &'static str,
    #[serde(flatten)]
    point: &'a Point,
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |source| Error::Io {
        path: path.display().to_string(),
        source,
    }
}

/// Appends records to a log.
pub struct Writer {
    file: std::fs::File,
    path: PathBuf,
}

impl Writer {
    /// Starts the log with `header`: a new file (replacing any), or appended to
    /// the existing one.
    pub fn create(path: &Path, header: &Header, append: bool) -> Result<Self> {
        if append {
            drop_incomplete_line(path)?;
        }
        let file = std::fs::OpenOptions::new()
            .create(true)
            .write(true)
            .append(append)
            .truncate(!append)
            .open(path)
            .map_err(io(path))?;
        let mut w = Self {
            file,
            path: path.to_path_buf(),
        };
        w.line(header)?;
        Ok(w)
    }

    pub fn append(&mut self, point: &Point) -> Result<()> {
        self.line(&PointRecord {
            record: "point",
            point,
        })
    }

    /// One line, written whole, flushed and synced.
    fn line(&mut self, value: &impl Serialize) -> Result<()> {
        let mut text = serde_json::to_string(value)
            .map_err(|e| Error::Input(format!("{}: {e}", self.path.display())))?;
        text.push('\n');
        self.file
            .write_all(text.as_bytes())
            .and_then(|()| self.file.flush())
            .and_then(|()| self.file.sync_data())
            .map_err(io(&self.path))
    }
}

/// An exclusive lock on a points log (`flock`, also across NFS clients), held
/// by the run that writes it: a second sweep into the same log is refused
/// before any work instead of interleaving its lines. Released when dropped
/// (or when the process dies, however); a log still empty then is removed.
pub struct Lock {
    file: std::fs::File,
    path: PathBuf,
}

impl Lock {
    pub fn acquire(path: &Path) -> Result<Self> {
        use std::os::fd::AsRawFd;
        let file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .map_err(io(path))?;
        // SAFETY: flock on a file descriptor this function owns.
        if unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } != 0 {
            let e = std::io::Error::last_os_error();
            if e.raw_os_error() == Some(libc::EWOULDBLOCK) {
                return Err(Error::Input(format!(
                    "{}: another dermis sweep is writing this log now; wait for it to finish, \
                     or give this one another --out-dir (or --shard)",
                    path.display()
                )));
            }
            return Err(io(path)(e));
        }
        Ok(Self {
            file,
            path: path.to_path_buf(),
        })
    }
}

impl Drop for Lock {
    fn drop(&mut self) {
        if self.file.metadata().is_ok_and(|m| m.len() == 0) {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Cuts a last line that has no newline (a killed writer's) off the file.
fn drop_incomplete_line(path: &Path) -> Result<()> {
    let Ok(bytes) = std::fs::read(path) else {
        return Ok(());
    };
    let keep = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    if keep < bytes.len() {
        let file = std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .map_err(io(path))?;
        file.set_len(keep as u64).map_err(io(path))?;
    }
    Ok(())
}

/// One run in a log: its header and the points after it (until the next header).
#[derive(Clone, Debug)]
pub struct Segment {
    pub file: PathBuf,
    pub header: Header,
    pub points: Vec<Point>,
}

/// Reads a log. A last line cut short (a killed writer) is skipped with a
/// warning; any other line that does not parse is an error naming it.
pub fn read(path: &Path, warnings: &mut Vec<String>) -> Result<Vec<Segment>> {
    let text = std::fs::read_to_string(path).map_err(io(path))?;
    let bad = |line: usize, why: String| Error::Input(format!("{}:{line}: {why}", path.display()));
    let mut segments: Vec<Segment> = Vec::new();
    let lines: Vec<&str> = text.split('\n').collect();
    for (i, line) in lines.iter().enumerate() {
        let n = i + 1;
        if line.trim().is_empty() {
            continue;
        }
        let value: serde_json::Value = match serde_json::from_str(line) {
            Ok(v) => v,
            // The final line with no newline after it: cut short.
            Err(e) if i + 1 == lines.len() => {
                warnings.push(format!(
                    "{}:{n}: skipped an incomplete last line ({e})",
                    path.display()
                ));
                continue;
            }
            Err(e) => return Err(bad(n, e.to_string())),
        };
        match value.get("record").and_then(|r| r.as_str()) {
            Some("header") => {
                let header: Header =
                    serde_json::from_value(value).map_err(|e| bad(n, format!("header: {e}")))?;
                segments.push(Segment {
                    file: path.to_path_buf(),
                    header,
                    points: Vec::new(),
                });
            }
            Some("point") => {
                let point: Point =
                    serde_json::from_value(value).map_err(|e| bad(n, format!("point: {e}")))?;
                segments
                    .last_mut()
                    .ok_or_else(|| bad(n, "a point before any header".into()))?
                    .points
                    .push(point);
            }
            other => return Err(bad(n, format!("unknown record {other:?}"))),
        }
    }
    if segments.is_empty() {
        return Err(Error::Input(format!(
            "{}: no header (not a dermis sweep points log?)",
            path.display()
        )));
    }
    Ok(segments)
}

/// The points a log already holds for `sweep_hash` (for `--resume`); the last
/// of several with one id. No log yet: none.
pub fn completed(path: &Path, sweep_hash: &str) -> Result<Vec<Point>> {
    // No log, or one a killed run left empty: nothing done.
    match std::fs::metadata(path) {
        Ok(m) if m.len() > 0 => {}
        _ => return Ok(Vec::new()),
    }
    let mut warnings = Vec::new();
    let segments = read(path, &mut warnings)?;
    for w in warnings {
        log::warn!("{w}");
    }
    if let Some(other) = segments.iter().find(|s| s.header.sweep_hash != sweep_hash) {
        return Err(Error::Input(format!(
            "--resume: {} holds sweep {}, not this sweep ({sweep_hash}): its options differ; \
             use another --out-dir, or run without --resume to start over",
            path.display(),
            other.header.sweep_hash
        )));
    }
    let mut out: Vec<Point> = Vec::new();
    for s in segments {
        for p in s.points {
            out.retain(|o| o.id != p.id);
            out.push(p);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("dermis-log-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    const HEADER: &str = r#"{"record":"header","schema_version":1,"sweep_hash":"00000000000000aa","shard":"all","shard_points":["r256-deon7-full"],"sweep_points":["r256-deon7-full"],"run_id":"r","timestamp":"2026-11-25T10:00:00Z","dermis_version":"0","git_commit":"c","fingerprint":{"device":"d","device_type":"CPU","driver":"","api_version":"","cpu_model":"","cpu_cores":2,"lp_num_threads":null,"clock":"","validation":false},"reference_checksum":"0","reference":{"resolution":256,"kernel":"accurate","chain":"full"},"scene":"builtin","environment":"sky","width":1,"height":1,"frames":2}"#;
    const POINT: &str = r#"{"record":"point","id":"r256-deon7-full","resolution":256,"kernel":"deon7","chain":"full","passes":[],"total_ms":1.0,"chain_ms":0.5,"frame_span":{"name":"frame","frames":0,"texels":null,"bytes":null,"ns_per_texel":null,"gb_per_s":null,"x_ruler":null},"transient_bytes":0,"final_error":{"rmse_rel":0.1,"max_rel":0.2,"p99_rel":0.15,"psnr_db":30.0,"pixels":4},"diffuse_error":{"rmse_rel":0.1,"max_rel":0.2,"p99_rel":0.15,"psnr_db":null,"pixels":4}}"#;

    #[test]
    fn reads_runs_and_skips_only_a_cut_last_line() {
        let d = dir("read");
        let path = d.join("points.jsonl");
        // A second run appended after a first cut short inside its point.
        let cut = &POINT[..40];
        std::fs::write(&path, format!("{HEADER}\n{POINT}\n{HEADER}\n{cut}")).unwrap();
        let mut warnings = Vec::new();
        let runs = read(&path, &mut warnings).unwrap();
        assert_eq!(runs.len(), 2);
        assert_eq!(runs[0].points.len(), 1);
        assert_eq!(runs[0].points[0].final_error.psnr_db, Some(30.0));
        assert!(runs[1].points.is_empty());
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        // The same cut in the middle is an error naming the line.
        std::fs::write(&path, format!("{HEADER}\n{cut}\n{POINT}\n")).unwrap();
        let e = read(&path, &mut Vec::new()).unwrap_err().to_string();
        assert!(e.contains("points.jsonl:2"), "{e}");
        // A point before any header, and no header at all.
        std::fs::write(&path, format!("{POINT}\n")).unwrap();
        assert!(read(&path, &mut Vec::new()).is_err());
        std::fs::write(&path, "\n").unwrap();
        assert!(read(&path, &mut Vec::new()).is_err());
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// Errors read back from a log are the very numbers written (serde_json's
    /// float_roundtrip): a merged or resumed sweep.json equals the shards' logs
    /// to the last digit (without it …386 came back as …383).
    #[test]
    fn numbers_survive_the_log_bit_for_bit() {
        let d = dir("roundtrip");
        let path = d.join("points.jsonl");
        let header: Header = serde_json::from_str(HEADER).unwrap();
        let mut point: Point = serde_json::from_str(POINT).unwrap();
        let mut w = Writer::create(&path, &header, false).unwrap();
        // xorshift: 2000 errors spread over many magnitudes.
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut written = Vec::new();
        for _ in 0..2000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = (x >> 11) as f64 / (1u64 << 53) as f64 * 10f64.powi((x % 9) as i32 - 6);
            point.final_error.max_rel = v;
            point.total_ms = 1.0 / (v + 1e-3);
            w.append(&point).unwrap();
            written.push((v, point.total_ms));
        }
        drop(w);
        let runs = read(&path, &mut Vec::new()).unwrap();
        let back: Vec<(f64, f64)> = runs[0]
            .points
            .iter()
            .map(|p| (p.final_error.max_rel, p.total_ms))
            .collect();
        let differ = written
            .iter()
            .zip(&back)
            .filter(|(a, b)| a.0.to_bits() != b.0.to_bits() || a.1.to_bits() != b.1.to_bits())
            .count();
        assert_eq!(differ, 0, "{differ} of {} numbers changed", written.len());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_second_writer_of_one_log_is_refused() {
        let d = dir("lock");
        let path = d.join("points.jsonl");
        let held = Lock::acquire(&path).unwrap();
        let e = Lock::acquire(&path).err().unwrap();
        assert_eq!(e.exit_code(), 2);
        assert!(e.to_string().contains("another dermis sweep"), "{e}");
        drop(held);
        // Released, and the empty log it created is gone.
        assert!(!path.exists());
        let again = Lock::acquire(&path).unwrap();
        std::fs::write(&path, "x\n").unwrap();
        drop(again);
        assert!(path.exists(), "a log with content stays");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn resuming_cuts_the_incomplete_line_and_refuses_another_sweep() {
        let d = dir("resume");
        let path = d.join("points.jsonl");
        std::fs::write(&path, format!("{HEADER}\n{POINT}\n{}", &POINT[..40])).unwrap();
        assert_eq!(completed(&path, "00000000000000aa").unwrap().len(), 1);
        let e = completed(&path, "00000000000000bb")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("--resume") && e.contains("00000000000000aa"),
            "{e}"
        );
        assert!(completed(&d.join("none.jsonl"), "x").unwrap().is_empty());
        let header: Header = serde_json::from_str(HEADER).unwrap();
        let point: Point = serde_json::from_str(POINT).unwrap();
        let mut w = Writer::create(&path, &header, true).unwrap();
        w.append(&point).unwrap();
        drop(w);
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.lines().count(), 4, "{text}");
        let runs = read(&path, &mut Vec::new()).unwrap();
        assert_eq!(
            runs.iter().map(|r| r.points.len()).collect::<Vec<_>>(),
            [1, 1]
        );
        // Without append the log starts over.
        Writer::create(&path, &header, false).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap().lines().count(), 1);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
