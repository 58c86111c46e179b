//! `dermis info`, `sh` and `lights`: the device and an environment, no scene.

use clap::Args;
use dermis::gpu::{Context, ContextOptions};
use dermis::light::extract;
use dermis::scene::env::{self, EnvMap, EnvSource};
use dermis::scene::file::{parse_env_source, LightsMode};

#[derive(Args)]
pub struct InfoArgs {
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

/// An environment given as the positional `ENV`.
#[derive(Args)]
pub struct EnvArg {
    /// A .hdr/.exr file, a cross, `cube:...`, `uniform:R,G,B` or `sky[:...]`.
    #[arg(value_parser = named_env)]
    env: NamedEnv,
}

/// A source as parsed and as given (printed back as given).
#[derive(Clone)]
struct NamedEnv {
    text: String,
    source: EnvSource,
}

fn named_env(s: &str) -> Result<NamedEnv, String> {
    Ok(NamedEnv {
        text: s.to_string(),
        source: parse_env_source(s)?,
    })
}

impl EnvArg {
    /// The map, procedural sources at `PROCEDURAL_ENV_SIZE`.
    fn map(&self) -> dermis::Result<EnvMap> {
        let (w, h) = dermis::scene::PROCEDURAL_ENV_SIZE;
        Ok(env::resolve(&self.env.source, w, h)?.0)
    }
}

#[derive(Args)]
pub struct ShArgs {
    #[command(flatten)]
    env: EnvArg,
    /// Rotation about +Y, degrees.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = finite)]
    rotate: f32,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    /// Also print the GPU passes' timings.
    #[arg(long)]
    timings: bool,
}

#[derive(Args)]
pub struct LightsArgs {
    #[command(flatten)]
    env: EnvArg,
    /// Rotation of the environment about +Y, degrees (as `environment.rotation_deg`).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = finite)]
    rotate: f32,
    /// `auto` (compact sources holding ≥ 5 % of the energy) or the N strongest (0..=8).
    #[arg(
        long,
        default_value = "auto",
        value_name = "auto|N",
        allow_hyphen_values = true
    )]
    lights: LightsMode,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

/// A finite number (clap's error, exit status 2, names the flag).
fn finite(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(format!("{v} is not a finite number")),
        Err(e) => Err(e.to_string()),
    }
}

/// `dermis info`.
pub fn info(args: InfoArgs, context: &ContextOptions) -> dermis::Result<()> {
    let ctx = Context::new(context)?;
    let info = &ctx.info;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(info).unwrap_or_default());
        return Ok(());
    }
    outln!("device:            {} ({})", info.name, info.device_type);
    outln!(
        "driver:            {} {}",
        info.driver_name,
        info.driver_info
    );
    outln!("Vulkan:            {}", info.api_version);
    outln!(
        "timestamps:        {} (period {} ns, {} valid bits)",
        if info.timestamps { "yes" } else { "no" },
        info.timestamp_period_ns,
        info.timestamp_valid_bits
    );
    outln!("max image size:    {}", info.max_image_dimension_2d);
    for (i, h) in info.memory_heaps.iter().enumerate() {
        outln!(
            "memory heap {i}:     {:.1} GiB{}",
            h.size_bytes as f64 / (1u64 << 30) as f64,
            if h.device_local {
                " (device local)"
            } else {
                ""
            }
        );
    }
    Ok(())
}

/// `dermis sh`.
pub fn sh(args: ShArgs, context: &ContextOptions) -> dermis::Result<()> {
    let map = args.env.map()?;
    let ctx = Context::new(context)?;
    let (coeffs, report) = dermis::light::sh_pass::project(&ctx, &map, args.rotate, 1.0)?;
    let names = [
        "L00", "L1-1", "L10", "L11", "L2-2", "L2-1", "L20", "L21", "L22",
    ];
    if args.json {
        let obj: serde_json::Map<String, serde_json::Value> = names
            .iter()
            .zip(&coeffs)
            .map(|(n, c)| (n.to_string(), serde_json::json!([c.x, c.y, c.z])))
            .collect();
        let out = serde_json::json!({
            "environment": args.env.env.text,
            "rotation_deg": args.rotate,
            "order": names,
            "coefficients": obj,
        });
        outln!("{}", serde_json::to_string_pretty(&out).unwrap_or_default());
    } else {
        for (n, c) in names.iter().zip(&coeffs) {
            outln!("{n:<5} {:>14.6} {:>14.6} {:>14.6}", c.x, c.y, c.z);
        }
    }
    if args.timings {
        eprint!("{}", report.table());
    }
    Ok(())
}

/// `dermis lights`.
pub fn lights(args: LightsArgs) -> dermis::Result<()> {
    let LightsArgs {
        env,
        rotate,
        lights,
        json,
    } = args;
    let found = extract::extract(&env.map()?, lights).lights;
    let residual = 1.0 - found.iter().map(|l| l.share).sum::<f32>();
    let rows: Vec<_> = found
        .iter()
        .map(|l| {
            let d = l.world_direction(rotate);
            let (elevation, azimuth) = extract::elevation_azimuth_deg(d);
            (l, d, elevation, azimuth)
        })
        .collect();
    if json {
        let lights_json: Vec<_> = rows
            .iter()
            .map(|(l, d, elevation, azimuth)| {
                serde_json::json!({
                    "direction": [d.x, d.y, d.z],
                    "elevation_deg": elevation,
                    "azimuth_deg": azimuth,
                    "solid_angle_sr": l.solid_angle_sr,
                    "angular_radius_deg": l.angular_radius_rad.to_degrees(),
                    "power": [l.power.x, l.power.y, l.power.z],
                    "share": l.share,
                    "texels": l.texels,
                })
            })
            .collect();
        let out = serde_json::json!({
            "environment": env.env.text,
            "rotation_deg": rotate,
            "mode": lights,
            "lights": lights_json,
            "residual_share": residual,
        });
        outln!("{}", serde_json::to_string_pretty(&out).unwrap_or_default());
        return Ok(());
    }
    outln!(
        "{}, rotated {rotate}°, lights {lights}: {} found",
        env.env.text,
        rows.len()
    );
    if !rows.is_empty() {
        outln!(
            "{:>2} {:>9} {:>8}  {:<24}  {:>11} {:>7}  {:<30}  {:>7}",
            "#",
            "elevation",
            "azimuth",
            "direction (world)",
            "solid angle",
            "radius",
            "power (R, G, B)",
            "share"
        );
    }
    for (i, (l, d, elevation, azimuth)) in rows.iter().enumerate() {
        outln!(
            "{:>2} {:>8.2}° {:>7.2}°  ({:>6.3}, {:>6.3}, {:>6.3})  {:>8.5} sr {:>6.2}°  \
             ({:>8.4}, {:>8.4}, {:>8.4})  {:>5.1} %",
            i + 1,
            elevation,
            azimuth,
            d.x,
            d.y,
            d.z,
            l.solid_angle_sr,
            l.angular_radius_rad.to_degrees(),
            l.power.x,
            l.power.y,
            l.power.z,
            100.0 * l.share
        );
    }
    outln!("residual: {:.1} % of the energy", 100.0 * residual);
    Ok(())
}
