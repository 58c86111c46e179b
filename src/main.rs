//! The `dermis` command line: parses and dispatches; each command is a function
//! of `cli/`, the rendering logic lives in the library.

mod cli;

use clap::{CommandFactory, Parser, Subcommand};
use cli::{compare, inspect, manual, medium, reference, render, sweep, view, AFTER_HELP};
use dermis::gpu::ContextOptions;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "dermis",
    version,
    about = "Realistic face rendering on Vulkan, measured pass by pass",
    after_help = AFTER_HELP,
    subcommand_help_heading = "Commands"
)]
struct Cli {
    /// Use the first Vulkan device whose name contains this (case-insensitive).
    #[arg(long, global = true, env = "DERMIS_DEVICE")]
    device: Option<String>,
    /// Enable the Khronos validation layer with synchronization validation; any
    /// message it reports fails the run (exit status 4).
    #[arg(long, global = true, env = "DERMIS_VALIDATION", value_parser = clap::builder::BoolishValueParser::new())]
    validation: bool,
    /// More log output (-v info, -vv debug); RUST_LOG overrides.
    #[arg(short, long, global = true, action = clap::ArgAction::Count)]
    verbose: u8,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Describe the Vulkan device dermis would use.
    #[command(after_help = AFTER_HELP)]
    Info(inspect::InfoArgs),
    /// Print an environment's 27 SH coefficients (9 per channel), projected on the GPU.
    #[command(after_help = AFTER_HELP)]
    Sh(inspect::ShArgs),
    /// List the bright sources (suns, softboxes) taken out of an environment as lights.
    ///
    /// Per light: its direction (world, after --rotate), elevation and azimuth,
    /// solid angle, angular radius, power (RGB irradiance at normal incidence) and
    /// share of the map's energy; then the residual's share (docs/design/lighting.md).
    /// Shares are fractions in --json. Runs on the CPU.
    #[command(after_help = AFTER_HELP)]
    Lights(inspect::LightsArgs),
    /// Print the scene's skin medium (--medium, `[skin.medium]`): its
    /// coefficients, albedo, the six Gaussians fitted to its R(r) with their
    /// error, and its light through slabs (docs/design/media.md). Runs on the CPU;
    /// the tables are cached.
    #[command(after_help = AFTER_HELP)]
    Medium(medium::MediumArgs),
    /// Compute (and cache) the per-vertex occlusion transfer, the specular's lobe visibility, and the interreflected and transmitted transfers ahead of rendering.
    ///
    /// The scene's mesh (--mesh, --mm-per-unit) and `skin.occlusion`
    /// (--occlusion) are used.
    #[command(after_help = AFTER_HELP)]
    Precompute(render::PrecomputeArgs),
    /// Time against quality: render every irradiance resolution × blur kernel ×
    /// diffusion chain with the rulers and compare each final image and diffuse
    /// term with a reference over the face (RMSE and max relative to the mean,
    /// 99th percentile, PSNR). Writes points.jsonl, sweep.csv, sweep.json,
    /// time_vs_error.{svg,png} and passes.{svg,png} into --out-dir; with --shard,
    /// only this shard's points-shard-I-of-N.jsonl, for `dermis sweep merge`
    /// (docs/guide/sweep.md, docs/recipes/).
    ///
    /// The scene's skybox is turned off: the face mask is the image's alpha.
    #[command(after_help = AFTER_HELP, args_conflicts_with_subcommands = true)]
    Sweep(sweep::SweepArgs),
    /// Lighting against the truth: for each environment, the direct term
    /// (`--view direct`, grey albedo) with the paper's SH9 alone and with the
    /// bright sources extracted as shadowed lights, each against the CPU
    /// reference (`--view reference`); prints the mean, median and 90th
    /// percentile of the per-pixel relative error over the mesh
    /// (docs/records/2026-11-25-sh9-against-reference.md).
    ///
    /// --env repeats, one comparison each (default: the scene's own).
    #[command(after_help = AFTER_HELP)]
    Reference(reference::ReferenceArgs),
    /// Open the interactive viewer: the scene in a window (winit, Vulkan
    /// swapchain) with an orbit camera, the paper's controls and live per-pass
    /// timings.
    ///
    /// Mouse and keys: left drag orbits, right or middle drag pans, the wheel
    /// zooms; Shift + left drag turns the environment; right click opens the
    /// controls; F12 writes a screenshot (PNG), R reloads the scene file, Esc
    /// quits. The window is --width (default: the scene's render width plus
    /// the panel's, 360) by --height (default: the scene's render height).
    #[command(after_help = AFTER_HELP)]
    View(view::ViewArgs),
    /// Compare two measurements pass by pass: the change of each pass's median
    /// (in ruler units where both sides ran --ruler, else ms), a bootstrap 95 %
    /// interval, a Mann-Whitney U p-value Holm-corrected over the passes, and a
    /// verdict: regressed / improved / unchanged / inconclusive (docs/guide/compare-in-ci.md,
    /// "Comparing runs").
    #[command(after_help = AFTER_HELP)]
    Compare(compare::CompareArgs),
    /// Run two binaries or two option sets alternately (A B B A A B …: drift
    /// cancels), each run a process of `render --frames F --ruler --report`, then
    /// compare them as `dermis compare` does.
    #[command(after_help = AFTER_HELP)]
    Interleave(compare::InterleaveArgs),
    /// Convert a run report for CI dashboards: github-action-benchmark
    /// (`customSmallerIsBetter`) and Bencher Metric Format JSON.
    #[command(after_help = AFTER_HELP)]
    Export(compare::ExportArgs),
    /// Print the JSON Schema of run reports (docs/report.schema.json).
    #[command(after_help = AFTER_HELP)]
    ReportSchema,
    /// Render a scene to an image (by default the scanned head, assets/default.toml).
    #[command(after_help = AFTER_HELP)]
    Render(render::RenderArgs),
    /// Print the command-line reference page (docs/reference/cli.md).
    #[command(hide = true)]
    CliReference(manual::ManualArgs),
}

fn main() -> ExitCode {
    // First, before any thread: an interrupted write leaves no temporary.
    dermis::atomic::clean_up_on_signals();
    let cli = Cli::parse();
    let level = match cli.verbose {
        0 => "warn",
        1 => "info",
        _ => "debug",
    };
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or(level)).init();
    match run(cli) {
        Ok(code) => match dermis::gpu::validation_messages() {
            0 => code,
            n => {
                eprintln!("error: the validation layer reported {n} message(s) (above)");
                ExitCode::from(VALIDATION_FAILED)
            }
        },
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code() as u8)
        }
    }
}

/// Exit status of a run that succeeded but drew validation messages (--validation).
const VALIDATION_FAILED: u8 = 4;

fn run(cli: Cli) -> dermis::Result<ExitCode> {
    let mut context = ContextOptions::from_env();
    context.validation |= cli.validation;
    context.device = cli.device.or(context.device);
    let done = match cli.command {
        Command::Info(args) => inspect::info(args, &context),
        Command::Sh(args) => inspect::sh(args, &context),
        Command::Lights(args) => inspect::lights(args),
        Command::Medium(args) => medium::medium(args),
        Command::Precompute(args) => render::precompute(args, &context),
        Command::Sweep(args) => sweep::sweep(args, &context),
        Command::Reference(args) => reference::reference(args, &context),
        Command::View(args) => view::view(args, context),
        Command::Compare(args) => return compare::compare(args),
        Command::Interleave(args) => return compare::interleave(args),
        Command::Export(args) => compare::export(args),
        Command::ReportSchema => compare::report_schema(),
        Command::Render(args) => render::render(args, &context),
        Command::CliReference(args) => manual::manual(args, Cli::command()),
    };
    done.map(|()| ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    /// clap's own checks (unique flags, valid attributes) of every command.
    #[test]
    fn the_command_line_is_consistent() {
        super::Cli::command().debug_assert();
    }
}
