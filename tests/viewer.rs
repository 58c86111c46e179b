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
        // A display number no other test run is likely to hold.
        let n = 90 + std::process::id() % 100;
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
