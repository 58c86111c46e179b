//! `dermis reference`: SH9 and extracted lights against the CPU reference.

use std::path::{Path, PathBuf};

use clap::{ArgAction, ArgMatches, Args, Command, FromArgMatches};
use dermis::fidelity::lighting_gap;
use dermis::gpu::{Context, ContextOptions};
use dermis::scene::env::EnvSource;
use dermis::scene::{Overrides, SceneArg};

use super::to_json;

#[derive(Args)]
pub struct ReferenceArgs {
    #[command(flatten)]
    scene: ReferenceScene,
    /// The reference's target relative standard error per pixel.
    #[arg(long, default_value_t = 0.005)]
    target_error: f32,
    /// Directory for each environment's images (EXR) and a PNG of the
    /// reference, SH9 and SH9 + lights side by side.
    #[arg(long)]
    out_dir: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Compare the skin's texture-space diffusion, full and adaptive chain,
    /// with the exact diffusion over the surface in 3-D (per face region, UV
    /// seams, shadow edges) instead of the lighting.
    #[arg(long)]
    diffusion: bool,
    /// With --diffusion: compare every STRIDE-th texel in u and v (default:
    /// the irradiance resolution / 256).
    #[arg(long, requires = "diffusion")]
    stride: Option<u32>,
}

/// The scene and its overrides, but `--env` repeats (one comparison each) and
/// the image is 96 × 120 by default: the reference is slow.
pub struct ReferenceScene {
    scene: SceneArg,
    overrides: Overrides,
    envs: Vec<EnvSource>,
}

impl Args for ReferenceScene {
    fn augment_args(cmd: Command) -> Command {
        Overrides::augment_args(SceneArg::augment_args(cmd))
            .mut_arg("env", |a| a.action(ArgAction::Append))
            .mut_arg("width", |a| a.default_value("96"))
            .mut_arg("height", |a| a.default_value("120"))
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

impl FromArgMatches for ReferenceScene {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let mut m = m.clone();
        let envs = m.remove_many::<EnvSource>("env");
        Ok(ReferenceScene {
            envs: envs.into_iter().flatten().collect(),
            scene: SceneArg::from_arg_matches_mut(&mut m)?,
            overrides: Overrides::from_arg_matches_mut(&mut m)?,
        })
    }

    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

/// `dermis reference`.
pub fn reference(args: ReferenceArgs, context: &ContextOptions) -> dermis::Result<()> {
    let ReferenceScene {
        scene,
        overrides,
        envs,
    } = args.scene;
    if let Some(dir) = &args.out_dir {
        super::check_out_dir("--out-dir", dir)?;
    }
    let file = scene.load(&overrides)?;
    let environments = if envs.is_empty() {
        vec![file.environment.source.clone()]
    } else {
        envs
    };
    if args.diffusion {
        return diffusion(
            file,
            environments,
            args.stride,
            args.out_dir,
            args.json,
            context,
        );
    }
    let target_error = args.target_error;
    if !(target_error > 0.0 && target_error < 1.0) {
        return Err(dermis::Error::Input(format!(
            "--target-error {target_error}: must be in (0, 1)"
        )));
    }
    let opts = lighting_gap::LightingOptions {
        width: file.render.width,
        height: file.render.height,
        scene: file,
        environments,
        settings: dermis::light::reference::Settings {
            target_rel_err: target_error,
            ..Default::default()
        },
        out_dir: args.out_dir,
    };
    let ctx = Context::new(context)?;
    let json = args.json;
    let rows = lighting_gap::run(&ctx, &opts, |r| {
        if !json {
            eprintln!(
                "{}: {} light(s) extracted; mean error {:.1} % → {:.1} % (reference {:.0} s)",
                r.environment,
                r.extracted,
                100.0 * r.sh9.mean,
                100.0 * r.sh9_lights.mean,
                r.reference_seconds
            );
        }
    })?;
    if json {
        outln!("{}", to_json(Path::new("stdout"), &rows)?);
    } else {
        out!("{}", lighting_gap::table(&rows));
    }
    Ok(())
}

/// `dermis reference --diffusion`.
fn diffusion(
    file: dermis::scene::file::SceneFile,
    environments: Vec<EnvSource>,
    stride: Option<u32>,
    out_dir: Option<PathBuf>,
    json: bool,
    context: &ContextOptions,
) -> dermis::Result<()> {
    use dermis::fidelity::diffusion_gap as d;
    use dermis::scene::file::Chain;
    let stride = stride.unwrap_or((file.render.irradiance_resolution / 256).max(1));
    if stride == 0 {
        return Err(dermis::Error::Input("--stride 0: give 1 or more".into()));
    }
    let ctx = Context::new(context)?;
    let mut rows = Vec::new();
    for (k, env) in environments.into_iter().enumerate() {
        let mut scene = file.clone();
        scene.environment.source = env;
        let opts = d::DiffusionOptions {
            scene,
            chains: vec![
                (Chain::Full, false),
                (Chain::Adaptive, false),
                (Chain::Adaptive, true),
            ],
            stride,
            out_dir: out_dir.as_ref().map(|dir| dir.join(k.to_string())),
        };
        rows.extend(d::run(&ctx, &opts, |r| {
            if !json {
                eprintln!(
                    "{} chain: reference in {:.0} s",
                    r.chain, r.reference_seconds
                );
            }
        })?);
    }
    if json {
        outln!("{}", to_json(Path::new("stdout"), &rows)?);
    } else {
        out!("{}", d::table(&rows));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: ReferenceArgs,
    }

    #[test]
    fn env_repeats_and_the_image_is_small_by_default() {
        let cli = Cli::try_parse_from(["dermis", "--env", "sky", "--env", "uniform:1"]).unwrap();
        let s = cli.args.scene;
        assert_eq!(s.envs.len(), 2);
        assert_eq!(s.envs[1], "uniform:1".parse().unwrap());
        assert_eq!(s.overrides.env, None);
        assert_eq!(
            (s.overrides.width, s.overrides.height),
            (Some(96), Some(120))
        );
        let cli = Cli::try_parse_from(["dermis", "--width", "64", "--exposure", "1"]).unwrap();
        let s = cli.args.scene;
        assert!(s.envs.is_empty());
        assert_eq!(
            (s.overrides.width, s.overrides.exposure),
            (Some(64), Some(1.0))
        );
    }
}
