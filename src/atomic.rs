//! Files written whole: each to a temporary name in its folder, flushed, then
//! renamed into place, so a reader (or a killed run) never sees half a file and
//! a failed write leaves the previous file as it was and no temporary behind.
//!
//! Temporaries in flight are registered: [`clean_up_on_signals`] (called first
//! thing by the binary) removes them when the process is interrupted (SIGINT,
//! SIGTERM, SIGHUP) before it dies of that signal. A process killed outright
//! (SIGKILL, a power cut) cannot; its temporaries are removed by the next
//! write into that folder from this machine ([`sweep_stale`]): a temporary's
//! name carries the writer's process id and a tag of its host, and one whose
//! process no longer runs on this host is stale.
//!
//! A symbolic link is written through: the file it points at is replaced and
//! the link kept.

use crate::error::{Error, Result};
use std::collections::HashSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard, OnceLock};

/// Paths to remove if the process is interrupted: temporaries being written,
/// probes. Held while a temporary is created or renamed, so the signal
/// thread sees each either absent or whole.
static IN_FLIGHT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn in_flight() -> MutexGuard<'static, Vec<PathBuf>> {
    IN_FLIGHT.lock().unwrap_or_else(|e| e.into_inner())
}

/// Eight hex digits of the FNV-1a of this machine's host name: temporaries of
/// other hosts (a shared folder) are never taken for stale.
fn host_tag() -> &'static str {
    static TAG: OnceLock<String> = OnceLock::new();
    TAG.get_or_init(|| {
        let mut buf = [0u8; 256];
        // SAFETY: the buffer is valid for its length; gethostname NUL-terminates
        // what fits.
        let ok = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) } == 0;
        let name = if ok {
            let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
            buf[..end].to_vec()
        } else {
            Vec::new()
        };
        let mut h: u32 = 0x811c_9dc5;
        for b in name {
            h = (h ^ u32::from(b)).wrapping_mul(0x0100_0193);
        }
        format!("{h:08x}")
    })
}

/// `dir/.name.tmp-PID-N-HOST.ext` for `dir/name.ext`: hidden, unique within
/// this process, in the same folder (a rename within one file system is
/// atomic).
fn temporary(path: &Path) -> PathBuf {
    static COUNT: AtomicU64 = AtomicU64::new(0);
    let n = COUNT.fetch_add(1, Ordering::Relaxed);
    let id = format!("tmp-{}-{n}-{}", std::process::id(), host_tag());
    let name = path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let tmp = match name.rsplit_once('.') {
        Some((stem, ext)) if !stem.is_empty() => format!(".{stem}.{id}.{ext}"),
        _ => format!(".{name}.{id}"),
    };
    path.with_file_name(tmp)
}

/// The writer of a temporary named by [`temporary`]: its process id and host
/// tag (`None` for the tag of names from before it had one).
fn writer_of(name: &str) -> Option<(u32, Option<&str>)> {
    if !name.starts_with('.') {
        return None;
    }
    let rest = &name[name.rfind(".tmp-")? + 5..];
    let mut parts = rest.splitn(3, '-');
    let pid = parts.next()?.parse::<u32>().ok()?;
    let tail = parts.next()?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    match parts.next() {
        // Legacy `.tmp-PID-N[.ext]`.
        None => digits(tail.split('.').next()?).then_some((pid, None)),
        Some(host) => {
            let tag = host.split('.').next()?;
            (digits(tail) && tag.len() == 8 && tag.bytes().all(|b| b.is_ascii_hexdigit()))
                .then_some((pid, Some(tag)))
        }
    }
}

/// Whether process `pid` runs on this machine.
fn alive(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else {
        return false;
    };
    // SAFETY: signal 0 only checks that the process exists.
    if unsafe { libc::kill(pid, 0) } == 0 {
        return true;
    }
    std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
}

/// Legacy temporaries (no host tag) are taken for stale only when this old.
const LEGACY_STALE: std::time::Duration = std::time::Duration::from_secs(3600);

/// Removes the temporaries in `dir` left by processes of this host that no
/// longer run (killed outright, mid-write); returns how many. Each folder is
/// swept once per process.
pub fn sweep_stale(dir: &Path) -> usize {
    static SWEPT: Mutex<Option<HashSet<PathBuf>>> = Mutex::new(None);
    {
        let mut swept = SWEPT.lock().unwrap_or_else(|e| e.into_inner());
        if !swept
            .get_or_insert_with(HashSet::new)
            .insert(dir.to_path_buf())
        {
            return 0;
        }
    }
    let Ok(entries) = std::fs::read_dir(if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    }) else {
        return 0;
    };
    let me = std::process::id();
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some((pid, tag)) = name.to_str().and_then(writer_of) else {
            continue;
        };
        let stale = pid != me
            && !alive(pid)
            && match tag {
                Some(tag) => tag == host_tag(),
                None => entry
                    .metadata()
                    .and_then(|m| m.modified())
                    .ok()
                    .and_then(|t| t.elapsed().ok())
                    .is_some_and(|age| age > LEGACY_STALE),
            };
        if stale
            && entry.file_type().is_ok_and(|t| t.is_file())
            && std::fs::remove_file(entry.path()).is_ok()
        {
            log::info!(
                "removed {}, a dead writer's temporary",
                entry.path().display()
            );
            removed += 1;
        }
    }
    removed
}

/// Where a write to `path` lands: `path`, or for a symbolic link the file it
/// points at (links followed, at most 40).
pub fn resolve_links(path: &Path) -> PathBuf {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => match std::fs::read_link(&p) {
                Ok(target) => p = p.parent().unwrap_or(Path::new("")).join(target),
                Err(_) => break,
            },
            _ => break,
        }
    }
    p
}

/// Checks that a file can be created beside `path` (the folder exists and is
/// writable): creates and removes a temporary there.
pub fn probe(path: &Path) -> std::io::Result<()> {
    let tmp = temporary(&resolve_links(path));
    create_registered(&tmp)?;
    forget(&tmp, true);
    Ok(())
}

fn create_registered(tmp: &Path) -> std::io::Result<std::fs::File> {
    let mut list = in_flight();
    let f = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(tmp)?;
    list.push(tmp.to_path_buf());
    Ok(f)
}

/// Takes `tmp` off the list, removing the file when `remove`.
fn forget(tmp: &Path, remove: bool) {
    let mut list = in_flight();
    if remove {
        let _ = std::fs::remove_file(tmp);
    }
    list.retain(|p| p != tmp);
}

/// Registers `path` for removal if the process is interrupted (a lock file, an
/// output written in place); [`unregister`] when done.
pub fn register(path: &Path) {
    in_flight().push(path.to_path_buf());
}

pub fn unregister(path: &Path) {
    forget(path, false);
}

/// For the tests that interrupt a write: milliseconds to wait with the
/// temporary written, before it is renamed into place.
pub const TEST_PAUSE_VAR: &str = "DERMIS_TEST_WRITE_PAUSE_MS";

fn test_pause() {
    if let Some(ms) = std::env::var(TEST_PAUSE_VAR)
        .ok()
        .and_then(|v| v.parse::<u64>().ok())
    {
        std::thread::sleep(std::time::Duration::from_millis(ms));
    }
}

/// Writes `bytes` to `path` atomically (see [`write_atomic_with`]).
pub fn write_atomic(path: &Path, bytes: impl AsRef<[u8]>) -> Result<()> {
    write_atomic_with(path, |f| f.write_all(bytes.as_ref()))
}

/// Writes what `write` puts into a temporary file (seekable: encoders may go
/// back) to `path`: flushed to disk, then renamed over `path` (over the file a
/// symbolic link points at, keeping the link). On any failure the temporary
/// file is removed and `path` is as it was.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut std::fs::File) -> std::io::Result<()>,
) -> Result<()> {
    let target = resolve_links(path);
    sweep_stale(target.parent().unwrap_or(Path::new("")));
    let tmp = temporary(&target);
    let mut created = false;
    let written = create_registered(&tmp).and_then(|mut f| {
        created = true;
        write(&mut f)?;
        test_pause();
        f.sync_all()?;
        drop(f);
        let _list = in_flight();
        std::fs::rename(&tmp, &target)
    });
    match written {
        Ok(()) => {
            forget(&tmp, false);
            Ok(())
        }
        Err(source) => {
            if created {
                forget(&tmp, true);
            }
            Err(Error::Io {
                path: path.display().to_string(),
                source,
            })
        }
    }
}

/// Removes the registered paths when the process gets SIGINT, SIGTERM or
/// SIGHUP, then dies of that signal (its parent sees what it would have).
///
/// The signals are blocked in the calling thread, and so in every thread it
/// starts afterwards (call it first, before any thread), and taken by one
/// thread of its own (`sigwait`), which may do anything a thread may: no
/// async-signal-safety concerns. Child processes start with the default mask
/// (`std::process::Command` resets it).
pub fn clean_up_on_signals() {
    const SIGNALS: [libc::c_int; 3] = [libc::SIGINT, libc::SIGTERM, libc::SIGHUP];
    // SAFETY: plain libc calls on a zeroed, then initialised, sigset_t.
    let set = unsafe {
        let mut set: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut set);
        for s in SIGNALS {
            libc::sigaddset(&mut set, s);
        }
        if libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut()) != 0 {
            return;
        }
        set
    };
    let spawned = std::thread::Builder::new()
        .name("dermis-signals".into())
        .spawn(move || {
            let mut sig: libc::c_int = 0;
            // SAFETY: `set` is initialised; sigwait writes the signal taken.
            while unsafe { libc::sigwait(&set, &mut sig) } != 0 {}
            // Held until the process ends: no temporary is created or renamed
            // after this point.
            let list = in_flight();
            for p in list.iter() {
                let _ = std::fs::remove_file(p);
            }
            std::mem::forget(list);
            // SAFETY: back to the default action, unblocked in this thread
            // only, then raised at this thread: the process ends of `sig`.
            unsafe {
                libc::signal(sig, libc::SIG_DFL);
                let mut one: libc::sigset_t = std::mem::zeroed();
                libc::sigemptyset(&mut one);
                libc::sigaddset(&mut one, sig);
                libc::pthread_sigmask(libc::SIG_UNBLOCK, &one, std::ptr::null_mut());
                libc::raise(sig);
            }
            std::process::exit(128 + sig);
        });
    if spawned.is_err() {
        // No thread to take them: let the signals act as before.
        // SAFETY: as above.
        unsafe {
            libc::pthread_sigmask(libc::SIG_UNBLOCK, &set, std::ptr::null_mut());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("dermis-atomic-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn names(d: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn temporaries_are_hidden_unique_and_keep_the_folder() {
        let (a, b) = (
            temporary(Path::new("out/sweep.json")),
            temporary(Path::new("out/sweep.json")),
        );
        assert_ne!(a, b);
        assert_eq!(a.parent(), Some(Path::new("out")));
        assert_eq!(a.extension().unwrap(), "json");
        let name = a.file_name().unwrap().to_string_lossy().into_owned();
        assert!(name.starts_with(".sweep.tmp-"), "{name}");
    }

    #[test]
    fn temporaries_name_their_writer() {
        let t = temporary(Path::new("out/big.exr"));
        let name = t.file_name().unwrap().to_str().unwrap();
        assert_eq!(
            writer_of(name),
            Some((std::process::id(), Some(host_tag()))),
            "{name}"
        );
        assert_eq!(writer_of(".big.tmp-12-0.exr"), Some((12, None)));
        assert_eq!(writer_of(".noext.tmp-12-3"), Some((12, None)));
        assert_eq!(
            writer_of(".a.tmp-b.tmp-7-1-0123abcd.json"),
            Some((7, Some("0123abcd")))
        );
        for not in [
            "big.exr",
            "big.tmp-12-0.exr",
            ".big.exr",
            ".big.tmp-x-0.exr",
            ".big.tmp-12-0-nothex!.exr",
            ".big.tmp-12.exr",
        ] {
            assert_eq!(writer_of(not), None, "{not}");
        }
    }

    /// A process that ran and ended: its id names no process (until reused).
    fn dead_pid() -> u32 {
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        child.wait().unwrap();
        assert!(!alive(pid));
        pid
    }

    #[test]
    fn the_next_write_sweeps_dead_writers_temporaries_of_this_host_only() {
        let d = folder("stale");
        let dead = dead_pid();
        let parent = std::os::unix::process::parent_id();
        let host = host_tag();
        let other = if host == "00000000" {
            "11111111"
        } else {
            "00000000"
        };
        let stale = format!(".big.tmp-{dead}-0-{host}.exr");
        let kept = [
            format!(".big.tmp-{parent}-0-{host}.exr"), // alive
            format!(".big.tmp-{dead}-1-{other}.exr"),  // another host's
            format!(".big.tmp-{dead}-2.exr"),          // legacy, recent
            "notes.tmp-1-2".to_string(),               // not ours
        ];
        for n in kept.iter().chain([&stale]) {
            std::fs::write(d.join(n), "half").unwrap();
        }
        write_atomic(&d.join("a.csv"), "x\n").unwrap();
        let mut want: Vec<String> = kept.to_vec();
        want.push("a.csv".into());
        want.sort();
        assert_eq!(names(&d), want);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_symbolic_link_is_written_through() {
        let d = folder("link");
        std::fs::create_dir_all(d.join("real")).unwrap();
        std::fs::write(d.join("real/out.png"), "old").unwrap();
        std::os::unix::fs::symlink("real/out.png", d.join("out.png")).unwrap();
        write_atomic(&d.join("out.png"), "new").unwrap();
        assert!(std::fs::symlink_metadata(d.join("out.png"))
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(
            std::fs::read_to_string(d.join("real/out.png")).unwrap(),
            "new"
        );
        assert_eq!(names(&d.join("real")), ["out.png"]);
        // A dangling link: the file it names is created.
        std::os::unix::fs::symlink("real/later.png", d.join("later.png")).unwrap();
        write_atomic(&d.join("later.png"), "made").unwrap();
        assert_eq!(
            std::fs::read_to_string(d.join("real/later.png")).unwrap(),
            "made"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_probe_says_whether_a_folder_takes_files_and_leaves_nothing() {
        let d = folder("probe");
        probe(&d.join("x.png")).unwrap();
        assert!(names(&d).is_empty());
        assert!(probe(Path::new("/proc/x.png")).is_err());
        assert!(probe(&d.join("no/such/x.png")).is_err());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn atomic_writes_leave_only_the_file() {
        let d = folder("whole");
        write_atomic(&d.join("a.csv"), "x\n").unwrap();
        write_atomic(&d.join("a.csv"), "y\n").unwrap();
        assert_eq!(names(&d), ["a.csv"]);
        assert_eq!(std::fs::read_to_string(d.join("a.csv")).unwrap(), "y\n");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn an_interrupted_write_keeps_the_old_file_and_no_temporary() {
        let d = folder("interrupted");
        let path = d.join("report.json");
        write_atomic(&path, "old").unwrap();
        // Half the new content written, then the writer fails (a full disk).
        let e = write_atomic_with(&path, |f| {
            f.write_all(b"{\"half\": ")?;
            Err(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        assert!(e.to_string().contains("report.json"), "{e}");
        assert_eq!(e.exit_code(), 2);
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        assert_eq!(names(&d), ["report.json"]);
        // Into a folder that does not exist: an error, nothing created.
        assert!(write_atomic(&d.join("no/such.json"), "x").is_err());
        assert_eq!(names(&d), ["report.json"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_failed_rename_removes_the_temporary() {
        // The target is a non-empty folder: the rename fails after the write.
        let d = folder("rename");
        std::fs::create_dir_all(d.join("out.png/inside")).unwrap();
        assert!(write_atomic(&d.join("out.png"), "png").is_err());
        assert_eq!(names(&d), ["out.png"]);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
