//! The frame loop's progress bar on stderr: frames done of all, the last frame's
//! time. Shown at once for several frames, after ~1 s for one, never when off.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::thread::JoinHandle;
use std::time::Duration;

pub(super) struct Progress {
    bar: ProgressBar,
    reveal: Option<(mpsc::Sender<()>, JoinHandle<()>)>,
}

impl Progress {
    pub fn new(frames: u32, shown: bool) -> Self {
        if !shown {
            return Self {
                bar: ProgressBar::hidden(),
                reveal: None,
            };
        }
        let bar = ProgressBar::with_draw_target(Some(frames.into()), ProgressDrawTarget::hidden());
        if let Ok(style) =
            ProgressStyle::with_template("{spinner} frames {pos}/{len} [{bar:30}] {elapsed} {msg}")
        {
            bar.set_style(style.progress_chars("=> "));
        }
        let delay = Duration::from_secs(if frames > 1 { 0 } else { 1 });
        let (stop, stopped) = mpsc::channel();
        let shown = bar.clone();
        let thread = std::thread::spawn(move || {
            if let Err(RecvTimeoutError::Timeout) = stopped.recv_timeout(delay) {
                shown.set_draw_target(ProgressDrawTarget::stderr());
                shown.enable_steady_tick(Duration::from_millis(250));
            }
        });
        Self {
            bar,
            reveal: Some((stop, thread)),
        }
    }

    /// `done` frames have finished, the last one in `last_ns` (its GPU span).
    pub fn update(&self, done: usize, last_ns: Option<f64>) {
        self.bar.set_position(done as u64);
        if let Some(ns) = last_ns {
            self.bar.set_message(format!("last {:.1} ms", ns / 1e6));
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some((stop, thread)) = self.reveal.take() {
            let _ = stop.send(());
            let _ = thread.join();
        }
        self.bar.finish_and_clear();
    }
}
