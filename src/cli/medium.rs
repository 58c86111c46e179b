//! `dermis medium`: what the scene's skin medium gives — its coefficients, its
//! albedo, the chain's six Gaussians fitted to its R(r) and their error, and
//! its light through a slab by thickness — on the CPU (docs/design/media.md).

use clap::Args;
use dermis::scene::{Overrides, SceneArg};
use dermis::skin::medium::Medium;
use dermis::skin::medium_tables::MediumTables;
use dermis::skin::walk::{self, fresnel_dielectric};

#[derive(Args)]
pub struct MediumArgs {
    #[command(flatten)]
    scene: SceneArg,
    #[command(flatten)]
    overrides: Overrides,
    /// Slab thicknesses (mm) at which to print T(d) and walk the light through.
    #[arg(long, num_args = 1.., default_values_t = [0.5f32, 1.0, 2.0, 3.0, 5.0],
          value_parser = thickness)]
    thickness: Vec<f32>,
}

fn thickness(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 && v <= 100.0 => Ok(v),
        Ok(v) => Err(format!("{v} mm is not in (0, 100]")),
        Err(e) => Err(e.to_string()),
    }
}

/// Photons through each slab: 16 000 leaving scattered (±0.8 %).
const COUNT: u64 = 16_000;

pub fn medium(args: MediumArgs) -> dermis::Result<()> {
    let file = args.scene.load(&args.overrides)?;
    let rgb = |v: [f32; 3]| format!("{:.4} {:.4} {:.4}", v[0], v[1], v[2]);
    let Some(m) = Medium::from_spec(&file.skin.medium) else {
        let p = dermis::skin::profile::Profile::skin();
        outln!("medium: deon2007 (d'Eon & Luebke's six Gaussians; no medium)");
        for &d in &args.thickness {
            outln!(
                "T({d} mm) = Σ wᵢ exp(−d²/2vᵢ) = {}",
                rgb(p.transmittance(d).to_array())
            );
        }
        return Ok(());
    };
    outln!("sigma_a       {} mm^-1", rgb(m.sigma_a.to_array()));
    outln!("sigma_s'      {} mm^-1", rgb(m.sigma_s_prime.to_array()));
    outln!("g {}, ior {}", m.g, m.ior);
    outln!(
        "1/sigma_tr    {} mm (diffuse mean free path)",
        rgb(m.dmfp().to_array())
    );
    let started = std::time::Instant::now();
    let t = MediumTables::load_or_compute(&m, &dermis::cache::default_cache_dir());
    outln!(
        "tables        {:.2} s here (made in: walks {:.2} s, fits {:.2} s; cached in {})",
        started.elapsed().as_secs_f32(),
        t.walk_seconds,
        t.fit_seconds,
        dermis::cache::default_cache_dir().display()
    );
    outln!(
        "albedo        {} (of the light entering, the share that leaves)",
        rgb(t.albedo)
    );
    outln!(
        "fit error     {} (r-weighted L2 of R(r), relative)",
        rgb(t.fit_error)
    );
    outln!(
        "reference fit {} ({} Gaussians, for reference --diffusion)",
        rgb(t.reference_error),
        t.reference_gaussians.len()
    );
    outln!("variance mm²  weights R G B");
    for (v, w) in &t.gaussians {
        outln!("{v:>12.4}  {}", rgb(*w));
    }
    // Light arriving along the normal: the boundary's share enters, then the
    // walk's scattered and ballistic shares leave the far side.
    let enters = 1.0 - fresnel_dielectric(1.0, 1.0 / f64::from(m.ior));
    outln!("d mm   T(d) table (scattered)      walked: scattered             through (per unit irradiance)");
    for &d in &args.thickness {
        let walked = [0, 1, 2].map(|c| walk::slab_to_count(&m, c, f64::from(d), COUNT, 1 << 24));
        let scattered = walked.map(|s| s.scattered as f32);
        let through = walked.map(|s| (enters * (s.scattered + s.ballistic)) as f32);
        outln!(
            "{d:<6} {}   {}   {}",
            rgb(t.transmittance_at(d).to_array()),
            rgb(scattered),
            rgb(through)
        );
    }
    Ok(())
}
