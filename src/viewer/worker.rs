//! The viewer's render thread: frames of the skin pipeline are rendered here, on
//! demand, while the window thread keeps presenting the last one and the UI at
//! display rate. Jobs queue up and only the newest is rendered; a job whose
//! settings differ from the session's in more than the camera, the size, the
//! environment's rotation and the post-processing starts a new session (scene
//! loaded again, pipelines built again).

use crate::error::Result;
use crate::gpu::{Context, Image};
use crate::render::session::Session;
use crate::render::{Screen, View};
use crate::scene::camera::Camera;
use crate::scene::file::SceneFile;
use crate::scene::Scene;
use crate::timing::FrameTiming;
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Instant;

/// What to render.
#[derive(Clone, Debug)]
pub struct Job {
    pub file: SceneFile,
    pub view: View,
    pub camera: Camera,
    /// The frame's size, pixels.
    pub size: (u32, u32),
}

/// A rendered frame, or why there is none.
pub struct Done {
    pub frame: Result<Rendered>,
    /// Jobs it answers: this one and the older ones it was rendered instead of.
    answers: usize,
}

pub struct Rendered {
    pub image: Arc<Image>,
    pub report: Option<FrameTiming>,
    pub extracted_lights: usize,
    /// The session's views (render::session::Session::views).
    pub views: Vec<String>,
    /// Whether a new session was started for it (scene loaded, pipelines built).
    pub rebuilt: bool,
    /// Wall-clock time of the job, seconds.
    pub seconds: f64,
}

pub struct Worker {
    jobs: Option<Sender<Job>>,
    done: Receiver<Done>,
    thread: Option<JoinHandle<()>>,
    /// Jobs sent and not yet answered.
    pending: usize,
}

impl Worker {
    pub fn new(ctx: &Arc<Context>) -> Worker {
        let (jobs, inbox) = channel::<Job>();
        let (outbox, done) = channel();
        let ctx = ctx.clone();
        let thread = std::thread::spawn(move || serve(&ctx, &inbox, &outbox));
        Worker {
            jobs: Some(jobs),
            done,
            thread: Some(thread),
            pending: 0,
        }
    }

    pub fn send(&mut self, job: Job) {
        if let Some(jobs) = &self.jobs {
            if jobs.send(job).is_ok() {
                self.pending += 1;
            }
        }
    }

    /// The newest finished frame, if any finished since the last call.
    pub fn poll(&mut self) -> Option<Done> {
        let mut latest = None;
        while let Ok(done) = self.done.try_recv() {
            self.pending = self.pending.saturating_sub(done.answers);
            latest = Some(done);
        }
        latest
    }

    /// Whether every job sent has been answered (a skipped job by the newer
    /// one rendered instead).
    pub fn idle(&self) -> bool {
        self.pending == 0
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        // Closing the channel ends the thread after its current job.
        self.jobs.take();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The thread's loop: the newest job of those waiting, rendered; its answer
/// stands for the skipped ones too.
fn serve(ctx: &Arc<Context>, inbox: &Receiver<Job>, outbox: &Sender<Done>) {
    let mut session: Option<Session> = None;
    while let Ok(mut job) = inbox.recv() {
        let mut skipped = 0;
        while let Ok(newer) = inbox.try_recv() {
            job = newer;
            skipped += 1;
        }
        let started = Instant::now();
        let frame =
            render(ctx, &mut session, &job).map(|(image, report, extracted, rebuilt)| Rendered {
                image,
                report,
                extracted_lights: extracted,
                views: session
                    .as_ref()
                    .map_or_else(Vec::new, |s| s.views().to_vec()),
                rebuilt,
                seconds: started.elapsed().as_secs_f64(),
            });
        if frame.is_err() {
            // A failed rebuild leaves nothing usable behind.
            session = None;
        }
        let answers = 1 + skipped;
        if outbox.send(Done { frame, answers }).is_err() {
            return;
        }
    }
}

type Frame = (Arc<Image>, Option<FrameTiming>, usize, bool);

/// One job on `session`, started again when it cannot take the job's settings
/// (render::session::Session::update decides).
fn render(ctx: &Arc<Context>, session: &mut Option<Session>, job: &Job) -> Result<Frame> {
    let mut file = job.file.clone();
    // The test-texture view is the final image with the checker as albedo.
    file.textures.test_texture |= job.view == View::Screen(Screen::TestTexture);
    let taken = match session {
        Some(s) => s.update(&file)?,
        None => false,
    };
    if !taken {
        *session = None; // free the old one's memory first
        (file.render.width, file.render.height) = job.size;
        *session = Some(Session::new(
            ctx,
            crate::skin::with_medium_albedo(Scene::load(file)?),
        )?);
    }
    let s = session.as_mut().expect("made above");
    s.set_camera(job.camera, job.size)?;
    let (image, report) = s.render(&job.view)?;
    Ok((image, report, s.extracted_lights(), !taken))
}
