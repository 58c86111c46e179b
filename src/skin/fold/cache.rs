//! The fold term's cache: `fold-<key>.bin` in the cache folder, keyed by the
//! mesh, the levels and the irradiance's side, written whole or not at all.

use super::{FoldLevel, FoldTerm, Source, Target};
use crate::atomic::write_atomic;
use crate::cache::{fnv1a64, hex};
use crate::scene::mesh::Mesh;
use crate::skin::chain::Level;
use std::path::Path;
use std::time::Instant;

/// Changed with the term's rules, so that no cached term of older rules is read.
const VERSION: &str = "fold term 6";
/// The first bytes of a cached term.
const MAGIC: &[u8; 8] = b"DRMFOLD1";

impl FoldTerm {
    /// The term from `cache_dir` (`fold-<key>.bin`, keyed by the mesh, the
    /// levels and the irradiance's side), else computed and stored there.
    pub fn load_or_compute(
        mesh: &Mesh,
        levels: &[Level],
        irradiance_side: u32,
        cache_dir: &Path,
    ) -> FoldTerm {
        let key = cache_key(mesh, levels, irradiance_side);
        let path = cache_dir.join(format!("fold-{}.bin", hex(key)));
        if let Ok(bytes) = std::fs::read(&path) {
            match FoldTerm::from_bytes(&bytes) {
                Some(term) => {
                    log::info!("fold term: loaded {}", path.display());
                    return term;
                }
                None => log::warn!("fold term: ignoring {}: not a whole term", path.display()),
            }
        }
        let started = Instant::now();
        let term = FoldTerm::compute(mesh, levels, irradiance_side);
        let (targets, sources) = term.size();
        log::info!(
            "fold term: {targets} texels, {sources} sources in {:.1} s",
            started.elapsed().as_secs_f64()
        );
        let stored = std::fs::create_dir_all(cache_dir)
            .map_err(|e| e.to_string())
            .and_then(|()| write_atomic(&path, term.to_bytes()).map_err(|e| e.to_string()));
        if let Err(e) = stored {
            log::warn!("fold term: cannot cache {}: {e}", path.display());
        }
        term
    }

    /// MAGIC, the level count, then per level its index, sides and list
    /// lengths (u32, little-endian) and the lists as stored on the GPU.
    pub(super) fn to_bytes(&self) -> Vec<u8> {
        let mut out = MAGIC.to_vec();
        out.extend((self.levels.len() as u32).to_le_bytes());
        for l in &self.levels {
            for n in [
                l.level as u32,
                l.side,
                l.source_side,
                l.targets.len() as u32,
                l.sources.len() as u32,
            ] {
                out.extend(n.to_le_bytes());
            }
            out.extend_from_slice(bytemuck::cast_slice(&l.targets));
            out.extend_from_slice(bytemuck::cast_slice(&l.sources));
        }
        out
    }

    /// [`FoldTerm::to_bytes`] read back; `None` unless whole and consistent.
    pub(super) fn from_bytes(bytes: &[u8]) -> Option<FoldTerm> {
        let mut r = Reader(bytes.strip_prefix(MAGIC)?);
        let mut term = FoldTerm::default();
        for _ in 0..r.u32()? {
            let [level, side, source_side, targets, sources] = [(); 5].map(|()| r.u32());
            let (targets, sources) = (targets? as usize, sources? as usize);
            let t: Vec<Target> =
                bytemuck::pod_collect_to_vec(r.take(targets * size_of::<Target>())?);
            let s: Vec<Source> =
                bytemuck::pod_collect_to_vec(r.take(sources * size_of::<Source>())?);
            if t.iter()
                .any(|t| t.first as usize + t.count as usize > s.len())
            {
                return None;
            }
            term.levels.push(FoldLevel {
                level: level? as usize,
                side: side?,
                source_side: source_side?,
                targets: t,
                sources: s,
            });
        }
        r.0.is_empty().then_some(term)
    }
}

/// The unread rest of a cached term.
struct Reader<'a>(&'a [u8]);

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let (head, tail) = (self.0.get(..n)?, self.0.get(n..)?);
        self.0 = tail;
        Some(head)
    }

    fn u32(&mut self) -> Option<u32> {
        self.take(4)
            .map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes")))
    }
}

/// The cache key: the mesh, the irradiance's side and every level's side and σ.
pub(super) fn cache_key(mesh: &Mesh, levels: &[Level], irradiance_side: u32) -> u64 {
    let floats = |v: &mut Vec<u8>, f: &[f32]| v.extend(f.iter().flat_map(|x| x.to_le_bytes()));
    let mut bytes = VERSION.as_bytes().to_vec();
    for p in mesh.positions.iter().chain(&mesh.normals) {
        floats(&mut bytes, &p.to_array());
    }
    for uv in &mesh.uvs {
        floats(&mut bytes, &uv.to_array());
    }
    bytes.extend(mesh.indices.iter().flat_map(|i| i.to_le_bytes()));
    bytes.extend(irradiance_side.to_le_bytes());
    for l in levels {
        bytes.extend(l.resolution.to_le_bytes());
        floats(&mut bytes, &[l.sigma_mm.unwrap_or(-1.0)]);
    }
    fnv1a64(&bytes)
}
