//! Progress on stderr. [`Progress`]: the frame loop's bar, frames done of all,
//! the last frame's time; shown at once for several frames, after ~1 s for one,
//! never when off. [`Task`]: a long job's (the CPU reference, a sweep), with the
//! time left, as a bar or as plain lines for logs.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::Mutex;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

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

/// A long job's progress on stderr with the time left, estimated from the rate
/// so far (in work units: rows, texels): a bar on a terminal, else a plain line
/// at every 10 % and at least every 5 s (CI logs). With no total (`0`): a spinner,
/// or a line when it starts and one when it ends.
pub struct Task {
    label: String,
    total: u64,
    started: Instant,
    bar: Option<ProgressBar>,
    /// Plain lines: work done, the next 10 % step to print at, the last line's time.
    plain: Option<Mutex<(u64, u64, Instant)>>,
}

impl Task {
    pub fn new(label: &str, total: u64) -> Task {
        let started = Instant::now();
        let (bar, plain) = if std::io::stderr().is_terminal() {
            let bar = ProgressBar::new(total);
            let template = if total == 0 {
                "{spinner} {prefix} {elapsed}"
            } else {
                "{spinner} {prefix} [{bar:30}] {percent:>3} % {elapsed}, about {eta} left"
            };
            if let Ok(style) = ProgressStyle::with_template(template) {
                bar.set_style(style.progress_chars("=> "));
            }
            bar.set_prefix(label.to_string());
            bar.enable_steady_tick(Duration::from_millis(250));
            (Some(bar), None)
        } else {
            eprintln!("{label}: started");
            (None, Some(Mutex::new((0, total / 10, started))))
        };
        Task {
            label: label.to_string(),
            total,
            started,
            bar,
            plain,
        }
    }

    /// `n` more units done (from any thread).
    pub fn add(&self, n: u64) {
        if let Some(bar) = &self.bar {
            bar.inc(n);
        }
        let Some(plain) = &self.plain else { return };
        let Ok(mut p) = plain.lock() else { return };
        let (done, next, last) = &mut *p;
        *done += n;
        if self.total == 0 || (*done < *next && last.elapsed() < Duration::from_secs(5)) {
            return;
        }
        let elapsed = self.started.elapsed().as_secs_f64();
        let left = elapsed * (self.total.saturating_sub(*done)) as f64 / (*done).max(1) as f64;
        eprintln!(
            "{}: {:.0} % ({}/{}), {} elapsed, about {} left",
            self.label,
            100.0 * *done as f64 / self.total as f64,
            *done,
            self.total,
            seconds(elapsed),
            seconds(left)
        );
        while *next <= *done {
            *next += (self.total / 10).max(1);
        }
        *last = Instant::now();
    }

    /// Runs `f` (which prints) with the bar out of the way.
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        match &self.bar {
            Some(bar) => bar.suspend(f),
            None => f(),
        }
    }
}

impl Drop for Task {
    fn drop(&mut self) {
        match &self.bar {
            Some(bar) => bar.finish_and_clear(),
            None => eprintln!(
                "{}: done in {}",
                self.label,
                seconds(self.started.elapsed().as_secs_f64())
            ),
        }
    }
}

/// `42 s`, `3 min 05 s`.
fn seconds(s: f64) -> String {
    let s = s.round() as u64;
    if s < 60 {
        format!("{s} s")
    } else {
        format!("{} min {:02} s", s / 60, s % 60)
    }
}
