//! `dermis view` in a real window: an X server (Xvfb) is started for the test,
//! the viewer renders 24 window frames of the scan at 960 × 640 with validation and
//! synchronization validation on, resizes its window halfway (the swapchain is
//! made again), and writes its last frame; the screenshot must show the face
//! and the layer must have said nothing. Without Xvfb the test fails, saying so:
//! CI installs it (`.ci/run`).

use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// An Xvfb server on a display number of its own, killed when dropped.
struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    fn start() -> Xvfb {
        // A display number no other test (of this run or another) is likely to hold.
        static NEXT: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
        // An X server killed without its clean-up (SIGKILL, as Drop does) leaves
        // its lock file and socket behind: a number holding either is skipped,
        // else the stale socket would pass for a server that never started.
        let free = |n: u32| {
            !PathBuf::from(format!("/tmp/.X{n}-lock")).exists()
                && !PathBuf::from(format!("/tmp/.X11-unix/X{n}")).exists()
        };
        let n = loop {
            let k = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let n = 90 + (std::process::id() % 100) * 4 + k;
            if free(n) {
                break n;
            }
        };
        let display = format!(":{n}");
        let child = Command::new("Xvfb")
            .args([&display, "-screen", "0", "1024x768x24", "-nolisten", "tcp"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| {
                panic!(
                    "cannot run Xvfb ({e}): the viewer test needs an X server; \
                     install it (Debian/Ubuntu: apt-get install xvfb), as .ci/run does"
                )
            });
        let socket = PathBuf::from(format!("/tmp/.X11-unix/X{n}"));
        let started = Instant::now();
        while !socket.exists() {
            assert!(
                started.elapsed() < Duration::from_secs(20),
                "Xvfb {display} did not come up"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
        Xvfb { child, display }
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[test]
fn the_viewer_shows_the_face_in_a_window_and_survives_a_resize() {
    let x = Xvfb::start();
    let dir = std::env::temp_dir().join(format!("dermis-viewer-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let shot = dir.join("view.png");
    let out = Command::new(env!("CARGO_BIN_EXE_dermis"))
        .args(["--validation", "view", "--irradiance-res", "256"])
        .args(["--width", "960", "--height", "640", "--frames", "24"])
        .arg("--screenshot")
        .arg(&shot)
        .env("DISPLAY", &x.display)
        .env("RUST_LOG", "warn")
        .output()
        .expect("dermis runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "dermis view failed: {stderr}");
    // The validation layer's messages go to the log at warning level or above.
    assert!(
        !stderr.contains("[validation]"),
        "validation reported:\n{stderr}"
    );
    let img = image::open(&shot).expect("the screenshot").to_rgba8();
    // Resized halfway: 960×640 → 720×480.
    assert_eq!(img.dimensions(), (720, 480), "the window was not resized");
    // Beside the control panel (on the left) the face fills the middle of the
    // rest: skin is red over blue, and the region is not one colour.
    let (w, h) = img.dimensions();
    let region: Vec<[f32; 3]> = (h / 4..3 * h / 4)
        .flat_map(|y| (w * 6 / 10..w * 9 / 10).map(move |x| (x, y)))
        .map(|(x, y)| {
            let p = img.get_pixel(x, y);
            [p[0] as f32, p[1] as f32, p[2] as f32]
        })
        .collect();
    let n = region.len() as f32;
    let mean = region.iter().fold([0.0; 3], |a, p| {
        [a[0] + p[0] / n, a[1] + p[1] / n, a[2] + p[2] / n]
    });
    let var = region.iter().map(|p| (p[0] - mean[0]).powi(2)).sum::<f32>() / n;
    println!("screenshot {w}×{h}: mean RGB {mean:?}, red variance {var:.0}");
    assert!(mean[0] > 40.0, "black: {mean:?}");
    assert!(var > 25.0, "constant: {var}");
    assert!(mean[0] > mean[2], "not skin: {mean:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_viewer_ends_and_writes_its_screenshot_in_tiny_windows() {
    let x = Xvfb::start();
    let dir = std::env::temp_dir().join(format!("dermis-viewer-tiny-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (w, h) in [(100, 100), (1, 1), (350, 200)] {
        let shot = dir.join(format!("view-{w}x{h}.png"));
        let mut child = Command::new(env!("CARGO_BIN_EXE_dermis"))
            .args(["--validation", "view", "--irradiance-res", "256"])
            .args(["--width", &w.to_string(), "--height", &h.to_string()])
            .args(["--frames", "6", "--screenshot"])
            .arg(&shot)
            .env("DISPLAY", &x.display)
            .env("RUST_LOG", "warn")
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("dermis runs");
        // Ends by itself: a hang fails here rather than holding the suite.
        let started = Instant::now();
        let status = loop {
            if let Some(s) = child.try_wait().unwrap() {
                break s;
            }
            if started.elapsed() > Duration::from_secs(600) {
                let _ = child.kill();
                panic!("dermis view at {w}×{h} did not end in 600 s");
            }
            std::thread::sleep(Duration::from_millis(100));
        };
        let mut stderr = String::new();
        std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut stderr).unwrap();
        assert!(status.success(), "{w}×{h}: {status}; stderr: {stderr}");
        assert!(!stderr.contains("[validation]"), "{w}×{h}:\n{stderr}");
        let img = image::open(&shot).expect("the screenshot").to_rgba8();
        let (iw, ih) = img.dimensions();
        assert!(
            iw >= 1 && ih >= 1 && iw <= w.max(1) && ih <= h.max(1),
            "{w}×{h}: {iw}×{ih}"
        );
        // The frame beside the panel holds more than the panel's colour
        // wherever there is room for it.
        if w >= 100 {
            let right = (iw / 2..iw)
                .flat_map(|x| (0..ih).map(move |y| (x, y)))
                .map(|(x, y)| *img.get_pixel(x, y))
                .collect::<std::collections::HashSet<_>>();
            assert!(
                right.len() > 4,
                "{w}×{h}: the right half is {} colours",
                right.len()
            );
        }
    }
}
