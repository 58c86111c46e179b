//! The points of a sweep in canonical order, each with a stable id, and the
//! sweep hash: one number over everything that makes two runs' points
//! comparable (and two shards' points parts of one sweep).

use super::shard::Shard;
use super::{name, SweepOptions, Variant};
use crate::cache::{fnv1a64, hex};
use crate::scene::file::{Chain, Kernel};
use serde::Serialize;

/// Bumped whenever the meaning of a point, its id, the JSONL records or the
/// hashed key changes; part of the sweep hash, and checked by `sweep merge`.
pub const SWEEP_SCHEMA_VERSION: u32 = 1;

impl Variant {
    /// `r1024-deon7-adaptive`: from the parameters only, so a point keeps its id
    /// whatever else the sweep contains.
    pub fn id(&self) -> String {
        format!(
            "r{}-{}-{}",
            self.resolution,
            name(&self.kernel),
            name(&self.chain)
        )
    }
}

/// The reference: the accurate kernel and the full chain at the reference
/// resolution.
pub fn reference(opts: &SweepOptions) -> Variant {
    Variant {
        resolution: opts.reference_resolution,
        kernel: Kernel::Accurate,
        chain: Chain::Full,
    }
}

/// Every point of the sweep in canonical order: resolution, then kernel, then
/// chain, each in the order given; a repeated value counts once.
pub fn variants(opts: &SweepOptions) -> Vec<Variant> {
    let mut out: Vec<Variant> = Vec::new();
    for &resolution in &opts.resolutions {
        for &kernel in &opts.kernels {
            for &chain in &opts.chains {
                let v = Variant {
                    resolution,
                    kernel,
                    chain,
                };
                if !out.iter().any(|o| o.id() == v.id()) {
                    out.push(v);
                }
            }
        }
    }
    out
}

/// What the sweep hash is computed over, serialised as compact JSON with the
/// fields in this order.
#[derive(Serialize)]
struct HashKey {
    schema_version: u32,
    points: Vec<String>,
    /// The resolved scene (skybox off), in its `Debug` form: `SceneFile` is not
    /// `Serialize`. Paths appear as resolved (relative to the working
    /// directory, or absolute), so shards must resolve them alike.
    scene: String,
    width: u32,
    height: u32,
    frames: u32,
    reference: String,
}

/// The canonical text the sweep hash is taken of (for `--list-points --json`
/// and for anyone re-deriving the hash).
pub fn hash_key(opts: &SweepOptions) -> String {
    let mut scene = opts.scene.clone();
    scene.render.skybox = false;
    let key = HashKey {
        schema_version: SWEEP_SCHEMA_VERSION,
        points: variants(opts).iter().map(Variant::id).collect(),
        scene: format!("{scene:?}"),
        width: opts.scene.render.width,
        height: opts.scene.render.height,
        frames: opts.frames,
        reference: reference(opts).id(),
    };
    serde_json::to_string(&key).unwrap_or_default()
}

/// The sweep hash: FNV-1a 64 of [`hash_key`], 16 hex digits.
pub fn sweep_hash(opts: &SweepOptions) -> String {
    hex(fnv1a64(hash_key(opts).as_bytes()))
}

/// What `dermis sweep --list-points --json` prints.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct PointList {
    pub schema_version: u32,
    pub sweep_hash: String,
    pub reference: String,
    /// `hash:2/3` when the list is one shard's; absent for the whole sweep.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard: Option<String>,
    /// The shard's points (all without one), canonical order.
    pub points: Vec<ListedPoint>,
}

#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct ListedPoint {
    pub id: String,
    #[serde(flatten)]
    pub variant: Variant,
}

/// The sweep's points, or `shard`'s.
pub fn list(opts: &SweepOptions, shard: Option<Shard>) -> PointList {
    PointList {
        schema_version: SWEEP_SCHEMA_VERSION,
        sweep_hash: sweep_hash(opts),
        reference: reference(opts).id(),
        shard: shard.map(|s| s.to_string()),
        points: variants(opts)
            .into_iter()
            .enumerate()
            .filter(|(i, v)| shard.is_none_or(|s| s.takes(*i, &v.id())))
            .map(|(_, variant)| ListedPoint {
                id: variant.id(),
                variant,
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::file::SceneFile;

    pub(crate) fn opts() -> SweepOptions {
        SweepOptions {
            scene: SceneFile::default(),
            scene_label: "builtin".into(),
            resolutions: vec![256, 1024],
            kernels: vec![Kernel::Deon7, Kernel::Accurate],
            chains: vec![Chain::Full, Chain::Adaptive],
            frames: 3,
            warmup_ms: None,
            reference_resolution: 2048,
        }
    }

    #[test]
    fn ids_follow_the_parameters_in_canonical_order() {
        let ids: Vec<String> = variants(&opts()).iter().map(Variant::id).collect();
        assert_eq!(
            ids,
            [
                "r256-deon7-full",
                "r256-deon7-adaptive",
                "r256-accurate-full",
                "r256-accurate-adaptive",
                "r1024-deon7-full",
                "r1024-deon7-adaptive",
                "r1024-accurate-full",
                "r1024-accurate-adaptive"
            ]
        );
        let mut twice = opts();
        twice.resolutions = vec![256, 256];
        assert_eq!(variants(&twice).len(), 4);
    }

    #[test]
    fn the_sweep_hash_follows_what_makes_points_comparable() {
        let base = sweep_hash(&opts());
        assert_eq!(base.len(), 16);
        assert_eq!(base, sweep_hash(&opts()), "deterministic");
        let changes: [fn(&mut SweepOptions); 6] = [
            |o| o.frames = 4,
            |o| o.reference_resolution = 4096,
            |o| o.resolutions.push(512),
            |o| o.scene.render.width += 1,
            |o| o.scene.skin.blur_width = 2.0,
            |o| o.kernels.reverse(),
        ];
        for (i, change) in changes.iter().enumerate() {
            let mut o = opts();
            change(&mut o);
            assert_ne!(sweep_hash(&o), base, "change {i}");
        }
        // The label (how the scene was named) and the skybox (always off) are not part of it.
        let mut o = opts();
        o.scene_label = "elsewhere".into();
        o.scene.render.skybox = !o.scene.render.skybox;
        assert_eq!(sweep_hash(&o), base);
    }
}
