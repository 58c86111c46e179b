//! `dermis view`.

use std::path::PathBuf;

use clap::Args;
use dermis::gpu::ContextOptions;
use dermis::scene::{Overrides, SceneArg};

#[derive(Args)]
pub struct ViewArgs {
    #[command(flatten)]
    scene: SceneArg,
    #[command(flatten)]
    overrides: Overrides,
    /// Render N window frames and exit (resizing the window once halfway,
    /// and waiting for the last render to be shown): for headless tests.
    #[arg(long)]
    frames: Option<u32>,
    /// Where the last frame of a --frames run (and F12) writes its PNG.
    #[arg(long)]
    screenshot: Option<PathBuf>,
}

/// `dermis view`.
pub fn view(args: ViewArgs, context: ContextOptions) -> dermis::Result<()> {
    if args.frames == Some(0) {
        return Err(dermis::Error::Input("--frames 0: give 1 or more".into()));
    }
    if let Some(path) = &args.screenshot {
        super::check_output("--screenshot", path, &["png"])?;
    }
    dermis::viewer::run(dermis::viewer::ViewerOptions {
        scene: args.scene.load(&args.overrides)?,
        scene_path: args.scene.scene,
        overrides: args.overrides,
        context,
        frames: args.frames,
        screenshot: args.screenshot,
    })
}
