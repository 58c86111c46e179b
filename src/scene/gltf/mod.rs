//! glTF 2.0 (.glb / .gltf) to one [`Mesh`] in millimetres.
//!
//! The default scene's node tree is walked with world transforms applied; every
//! triangle primitive is merged into one mesh. Accessors are decoded here with
//! checked arithmetic (not with the gltf crate's readers, which assume valid
//! offsets), so malformed files give an error instead of a panic.
//!
//! Conventions produced (see `mesh.rs`): positions in mm, unit normals, glTF UVs
//! (v down), tangents along +u with w such that `w * cross(n, t)` points toward
//! decreasing v (the top of the image), as glTF normal maps expect (glTF 2.0 spec
//! §3.7.2.1 "+Y is up"; the same sign three.js gets with `negateSign`).

use std::path::Path;

use glam::{Mat4, Vec2, Vec3, Vec4};
use gltf::mesh::Mode;

use super::file::SceneError;
use super::mesh::Mesh;

mod accessor;
mod buffers;
mod primitive;
mod tangents;

use buffers::load_buffers;
use primitive::read_primitive;

/// glTF 2.0 §3.4: "The units for all linear distances are meters."
const GLTF_MM_PER_UNIT: f32 = 1000.0;

/// A head (with or without neck and shoulders) is roughly 150–500 mm across;
/// outside this range the unit scale is probably wrong.
const PLAUSIBLE_HEAD_MM: std::ops::RangeInclusive<f32> = 100.0..=1000.0;

/// `x` in plain notation with at least three significant digits (0.000123,
/// 50.3, 12456): a scale hint for a huge mesh must not round to 0.000.
fn significant3(x: f32) -> String {
    if x == 0.0 || !x.is_finite() {
        return x.to_string();
    }
    let magnitude = (x.abs().log10().floor() as i32).clamp(-30, 30);
    format!("{x:.0$}", (2 - magnitude).max(0) as usize)
}

/// Refuse accessors with more elements than this (bounds memory on hostile input).
const MAX_ELEMENTS: usize = 1 << 26;

/// Accessors without a buffer view (zeros plus sparse values) are not bounded by
/// the file's size; cap them lower (256 MiB of VEC4 floats).
const MAX_VIEWLESS_ELEMENTS: usize = 1 << 24;

/// Deepest node hierarchy accepted.
const MAX_NODE_DEPTH: usize = 256;

/// Loads every triangle primitive of the default scene of a `.glb` or `.gltf` file.
///
/// `mm_per_unit` scales positions to millimetres; `None` assumes glTF's metres.
pub fn load_mesh(path: &Path, mm_per_unit: Option<f32>) -> Result<Mesh, SceneError> {
    let bytes = std::fs::read(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    load_mesh_from_slice(&bytes, path, mm_per_unit)
}

/// As [`load_mesh`] for file contents already in memory; `path` names the file in
/// messages and locates external buffers.
pub fn load_mesh_from_slice(
    bytes: &[u8],
    path: &Path,
    mm_per_unit: Option<f32>,
) -> Result<Mesh, SceneError> {
    let scale = match mm_per_unit {
        Some(s) if s.is_finite() && s > 0.0 => s,
        Some(s) => {
            return Err(SceneError::mesh(
                path,
                format!("mm_per_unit = {s}: must be a finite number greater than 0"),
            ))
        }
        None => {
            log::info!(
                "{}: no mm_per_unit given; assuming {GLTF_MM_PER_UNIT} mm per unit because \
                 glTF 2.0 specifies metres (spec §3.4)",
                path.display()
            );
            GLTF_MM_PER_UNIT
        }
    };
    let mesh = build_mesh(bytes, path, scale).map_err(|m| SceneError::mesh(path, m))?;
    if let Some((lo, hi)) = mesh.bounds() {
        let extent = (hi - lo).max_element();
        if !PLAUSIBLE_HEAD_MM.contains(&extent) {
            log::warn!(
                "{}: the mesh is {} mm across at {scale} mm per unit, implausible for a head \
                 ({}..{} mm); set mm_per_unit (about {} would make it 250 mm; the Lee \
                 Perry-Smith scan needs 50.3)",
                path.display(),
                significant3(extent),
                PLAUSIBLE_HEAD_MM.start(),
                PLAUSIBLE_HEAD_MM.end(),
                significant3(scale * 250.0 / extent.max(f32::MIN_POSITIVE)),
            );
        }
    }
    mesh.validate()
        .map_err(|m| SceneError::mesh(path, format!("invalid mesh: {m}")))?;
    let uv_area = mesh.uv_area();
    if uv_area < MIN_UV_AREA {
        return Err(SceneError::mesh(
            path,
            format!(
                "TEXCOORD_0 covers no texels (total UV area {uv_area:.3e}, less than one texel \
                 of a 1024² map): texture-space diffusion needs the mesh unwrapped over [0, 1]²"
            ),
        ));
    }
    Ok(mesh)
}

/// Least total UV area a mesh may have: one texel of a 1024² map.
const MIN_UV_AREA: f64 = 1.0 / (1024.0 * 1024.0);

/// One primitive in world millimetres, ready to merge.
pub(super) struct Part {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    tangents: Vec<Vec4>,
    indices: Vec<u32>,
}

fn build_mesh(bytes: &[u8], path: &Path, scale: f32) -> Result<Mesh, String> {
    let gltf = gltf::Gltf::from_slice(bytes).map_err(|e| format!("not a valid glTF file: {e}"))?;
    let doc = &gltf.document;
    let buffers = load_buffers(doc, gltf.blob.as_deref(), path)?;

    // Roots: the default scene, else the first scene, else every parentless node.
    let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => {
            let mut is_child = vec![false; doc.nodes().len()];
            for node in doc.nodes() {
                for child in node.children() {
                    if let Some(flag) = is_child.get_mut(child.index()) {
                        *flag = true;
                    }
                }
            }
            doc.nodes()
                .filter(|n| !is_child.get(n.index()).copied().unwrap_or(true))
                .collect()
        }
    };

    let mut parts = Vec::new();
    let mut skipped = 0usize;
    let mut name = None;
    let mut visited = vec![false; doc.nodes().len()];
    let mut stack: Vec<(gltf::Node, Mat4, usize)> =
        roots.into_iter().map(|n| (n, Mat4::IDENTITY, 0)).collect();
    while let Some((node, parent, depth)) = stack.pop() {
        let seen = visited
            .get_mut(node.index())
            .ok_or("node index out of range")?;
        if *seen {
            return Err(format!(
                "node {} is reached twice: the node hierarchy has a cycle or a shared child",
                node.index()
            ));
        }
        *seen = true;
        if depth > MAX_NODE_DEPTH {
            return Err(format!("node hierarchy deeper than {MAX_NODE_DEPTH}"));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        if let Some(mesh) = node.mesh() {
            let mesh_name = mesh.name().unwrap_or("unnamed");
            name.get_or_insert_with(|| mesh_name.to_string());
            for prim in mesh.primitives() {
                let what = format!("mesh '{mesh_name}' primitive {}", prim.index());
                if prim.mode() != Mode::Triangles {
                    log::warn!(
                        "{}: skipping {what}: mode {:?} is not triangles",
                        path.display(),
                        prim.mode()
                    );
                    skipped += 1;
                    continue;
                }
                let part = read_primitive(&prim, &buffers, world, scale, path)
                    .map_err(|m| format!("{what} (node {}): {m}", node.index()))?;
                parts.push(part);
            }
        }
        for child in node.children() {
            stack.push((child, world, depth + 1));
        }
    }
    if parts.is_empty() {
        return Err(if skipped > 0 {
            format!("no triangle primitives in the default scene ({skipped} non-triangle skipped)")
        } else {
            "no meshes in the default scene".into()
        });
    }

    // Merge, offsetting each part's indices.
    let mut out = Mesh {
        name: name.unwrap_or_else(|| {
            path.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        }),
        ..Mesh::default()
    };
    for part in parts {
        let base = u32::try_from(out.positions.len())
            .ok()
            .filter(|b| b.checked_add(part.positions.len() as u32).is_some())
            .ok_or("more than 2^32 vertices")?;
        out.indices.extend(part.indices.iter().map(|i| i + base));
        out.positions.extend(part.positions);
        out.normals.extend(part.normals);
        out.uvs.extend(part.uvs);
        out.tangents.extend(part.tangents);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::buffers::{decode_base64, percent_decode};
    use super::tangents::face_cross;
    use super::*;

    #[test]
    fn scale_hints_keep_three_significant_digits() {
        assert_eq!(significant3(0.000_123_4), "0.000123");
        assert_eq!(significant3(50.31), "50.3");
        assert_eq!(significant3(12456.0), "12456");
        assert_eq!(significant3(0.0), "0");
    }
    use std::path::PathBuf;

    fn lee_perry_smith() -> PathBuf {
        crate::assets::scan().join("LeePerrySmith.glb")
    }

    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!(
            "dermis-gltf-{name}-{}-{:?}",
            std::process::id(),
            std::time::SystemTime::now()
        ));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// A hand-made glTF: one primitive (optionally several nodes).
    #[derive(Clone, Default)]
    struct Doc {
        positions: Vec<[f32; 3]>,
        normals: Option<Vec<[f32; 3]>>,
        uvs: Option<Vec<[f32; 2]>>,
        tangents: Option<Vec<[f32; 4]>>,
        /// (component type 5121/5123/5125, values); None = non-indexed.
        indices: Option<(u32, Vec<u32>)>,
        mode: Option<u32>,
        /// JSON of the nodes array and the root list; default one plain node.
        nodes: Option<(String, String)>,
    }

    impl Doc {
        /// (JSON with buffer uri placeholder `@URI@`, binary buffer)
        fn build(&self) -> (String, Vec<u8>) {
            let mut bin: Vec<u8> = Vec::new();
            let mut views = Vec::new();
            let mut accessors = Vec::new();
            let mut attributes = Vec::new();
            let mut add = |bin: &mut Vec<u8>,
                           bytes: Vec<u8>,
                           comp: u32,
                           count: usize,
                           ty: &str,
                           extra: &str| {
                while !bin.len().is_multiple_of(4) {
                    bin.push(0);
                }
                views.push(format!(
                    r#"{{"buffer":0,"byteOffset":{},"byteLength":{}}}"#,
                    bin.len(),
                    bytes.len()
                ));
                bin.extend(bytes);
                accessors.push(format!(
                    r#"{{"bufferView":{},"componentType":{comp},"count":{count},"type":"{ty}"{extra}}}"#,
                    views.len() - 1
                ));
                accessors.len() - 1
            };
            let floats = |v: &[f32]| v.iter().flat_map(|f| f.to_le_bytes()).collect::<Vec<u8>>();
            let flat3: Vec<f32> = self.positions.iter().flatten().copied().collect();
            let extra = self.position_bounds();
            let a = add(
                &mut bin,
                floats(&flat3),
                5126,
                self.positions.len(),
                "VEC3",
                &extra,
            );
            attributes.push(format!(r#""POSITION":{a}"#));
            if let Some(n) = &self.normals {
                let f: Vec<f32> = n.iter().flatten().copied().collect();
                let a = add(&mut bin, floats(&f), 5126, n.len(), "VEC3", "");
                attributes.push(format!(r#""NORMAL":{a}"#));
            }
            if let Some(uv) = &self.uvs {
                let f: Vec<f32> = uv.iter().flatten().copied().collect();
                let a = add(&mut bin, floats(&f), 5126, uv.len(), "VEC2", "");
                attributes.push(format!(r#""TEXCOORD_0":{a}"#));
            }
            if let Some(t) = &self.tangents {
                let f: Vec<f32> = t.iter().flatten().copied().collect();
                let a = add(&mut bin, floats(&f), 5126, t.len(), "VEC4", "");
                attributes.push(format!(r#""TANGENT":{a}"#));
            }
            let mut indices = String::new();
            if let Some((comp, idx)) = &self.indices {
                let bytes: Vec<u8> = match comp {
                    5121 => idx.iter().map(|&i| i as u8).collect(),
                    5123 => idx.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect(),
                    _ => idx.iter().flat_map(|&i| i.to_le_bytes()).collect(),
                };
                let a = add(&mut bin, bytes, *comp, idx.len(), "SCALAR", "");
                indices = format!(r#","indices":{a}"#);
            }
            while !bin.len().is_multiple_of(4) {
                bin.push(0);
            }
            let mode = self
                .mode
                .map(|m| format!(r#","mode":{m}"#))
                .unwrap_or_default();
            let (nodes, roots) = self
                .nodes
                .clone()
                .unwrap_or((r#"[{"mesh":0}]"#.into(), "[0]".into()));
            let json = format!(
                r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":{roots}}}],
"nodes":{nodes},
"meshes":[{{"name":"test","primitives":[{{"attributes":{{{}}}{indices}{mode}}}]}}],
"buffers":[{{@URI@"byteLength":{}}}],
"bufferViews":[{}],
"accessors":[{}]}}"#,
                attributes.join(","),
                bin.len(),
                views.join(","),
                accessors.join(",")
            );
            (json, bin)
        }

        /// The POSITION accessor's `,"min":[..],"max":[..]` (glTF 2.0 §3.7.2.1:
        /// POSITION accessors must carry min and max); non-finite bounds as 0.
        fn position_bounds(&self) -> String {
            let (lo, hi) =
                self.positions
                    .iter()
                    .fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), p| {
                        (
                            [lo[0].min(p[0]), lo[1].min(p[1]), lo[2].min(p[2])],
                            [hi[0].max(p[0]), hi[1].max(p[1]), hi[2].max(p[2])],
                        )
                    });
            let bound = |v: [f32; 3]| {
                let v = v.map(|x| if x.is_finite() { x } else { 0.0 });
                format!("[{},{},{}]", v[0], v[1], v[2])
            };
            format!(r#","min":{},"max":{}"#, bound(lo), bound(hi))
        }

        /// Writes `<name>.gltf` + `<name>.bin` in `dir`.
        fn write_gltf(&self, dir: &Path, name: &str) -> PathBuf {
            let (json, bin) = self.build();
            let json = json.replace("@URI@", &format!(r#""uri":"{name}.bin","#));
            std::fs::write(dir.join(format!("{name}.bin")), bin).unwrap();
            let path = dir.join(format!("{name}.gltf"));
            std::fs::write(&path, json).unwrap();
            path
        }

        fn glb(&self) -> Vec<u8> {
            let (json, bin) = self.build();
            glb(json.replace("@URI@", "").as_bytes(), &bin)
        }
    }

    /// GLB container (glTF 2.0 §4.4): header, JSON chunk, BIN chunk.
    fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
        let mut json = json.to_vec();
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let total = 12 + 8 + json.len() + 8 + bin.len();
        let mut out = Vec::new();
        out.extend(b"glTF");
        out.extend(2u32.to_le_bytes());
        out.extend((total as u32).to_le_bytes());
        out.extend((json.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(&json);
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(bin);
        out
    }

    /// A unit square in the XY plane, two triangles; u along +X, glTF v along -Y.
    fn square() -> Doc {
        Doc {
            positions: vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
            normals: Some(vec![[0., 0., 1.]; 4]),
            uvs: Some(vec![[0., 1.], [1., 1.], [1., 0.], [0., 0.]]),
            indices: Some((5123, vec![0, 1, 2, 0, 2, 3])),
            ..Doc::default()
        }
    }

    fn load(doc: &Doc, mm: Option<f32>) -> Result<Mesh, SceneError> {
        load_mesh_from_slice(&doc.glb(), Path::new("test.glb"), mm)
    }

    fn assert_unit_frames(mesh: &Mesh) {
        for (n, t) in mesh.normals.iter().zip(&mesh.tangents) {
            assert!((n.length() - 1.0).abs() < 1e-4, "normal {n}");
            assert!((t.truncate().length() - 1.0).abs() < 1e-4, "tangent {t}");
            assert!(t.truncate().dot(*n).abs() < 1e-3, "t·n for {t} {n}");
            assert!(t.w == 1.0 || t.w == -1.0);
        }
    }

    /// Fraction of triangles whose tangent frame agrees with the UV gradient:
    /// t along +∂p/∂u and w·(n × t) along -∂p/∂v (glTF v points down).
    fn uv_agreement(mesh: &Mesh) -> f64 {
        let (mut good, mut total) = (0usize, 0usize);
        for tri in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| i as usize);
            let (p0, p1, p2) = (mesh.positions[a], mesh.positions[b], mesh.positions[c]);
            let (t0, t1, t2) = (mesh.uvs[a], mesh.uvs[b], mesh.uvs[c]);
            let (e1, e2) = (p1 - p0, p2 - p0);
            let (d1, d2) = (t1 - t0, t2 - t0);
            let det = d1.x * d2.y - d2.x * d1.y;
            if det.abs() < 1e-12 || (e1.cross(e2)).length() < 1e-9 {
                continue;
            }
            let dpdu = (e1 * d2.y - e2 * d1.y) / det;
            let dpdv = (e2 * d1.x - e1 * d2.x) / det;
            let t = mesh.tangents[a];
            let n = mesh.normals[a];
            let bitangent = n.cross(t.truncate()) * t.w;
            total += 1;
            if t.truncate().dot(dpdu) > 0.0 && bitangent.dot(-dpdv) > 0.0 {
                good += 1;
            }
        }
        good as f64 / total.max(1) as f64
    }

    #[test]
    fn lee_perry_smith_head() {
        let glb = lee_perry_smith();
        let start = std::time::Instant::now();
        let mesh = load_mesh(&glb, Some(50.3)).unwrap();
        println!("loaded {} in {:?}", glb.display(), start.elapsed());
        assert_eq!(mesh.name, "LeePerrySmith");
        assert_eq!(mesh.triangle_count(), 17_684);
        // 9,279 in the file; MikkTSpace may split a vertex whose corners differ.
        println!("vertices: {}", mesh.vertex_count());
        assert!(mesh.vertex_count() >= 9_279 && mesh.vertex_count() < 9_279 + 200);
        mesh.validate().unwrap();

        // README: 8.55 x 7.95 x 5.18 units = 430 x 400 x 260 mm at 50.3 mm/unit.
        let (lo, hi) = mesh.bounds().unwrap();
        let size = hi - lo;
        println!("bounds {size} mm");
        for (got, units) in [(size.x, 8.55), (size.y, 7.95), (size.z, 5.18)] {
            let want = units * 50.3;
            assert!((got / want - 1.0).abs() < 0.01, "{got} vs {want}");
        }

        assert_unit_frames(&mesh);
        let agree = uv_agreement(&mesh);
        println!("tangent frames agreeing with the UV gradient: {:.4}", agree);
        assert!(agree > 0.99, "{agree}");

        // The file's normals face the same way as the triangles' winding.
        let outward = mesh
            .indices
            .chunks_exact(3)
            .filter(|t| {
                let fnrm = face_cross(&mesh.positions, t);
                let vn = mesh.normals[t[0] as usize]
                    + mesh.normals[t[1] as usize]
                    + mesh.normals[t[2] as usize];
                fnrm.dot(vn) > 0.0
            })
            .count();
        assert!(outward as f64 > 0.99 * mesh.triangle_count() as f64);

        // Default units: metres, 1000 mm per unit.
        let metres = load_mesh(&glb, None).unwrap();
        let (lo2, hi2) = metres.bounds().unwrap();
        let ratio = (hi2 - lo2) / size;
        assert!((ratio - Vec3::splat(1000.0 / 50.3)).abs().max_element() < 0.01);
    }

    #[test]
    fn lee_perry_smith_as_gltf_with_external_bin() {
        let glb = lee_perry_smith();
        let bytes = std::fs::read(&glb).unwrap();
        // Split the GLB into its JSON and BIN chunks (glTF 2.0 §4.4).
        let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        let json = std::str::from_utf8(&bytes[20..20 + json_len]).unwrap();
        let bin = &bytes[20 + json_len + 8..];
        let json = json.replace(
            r#""buffers":[{"byteLength""#,
            r#""buffers":[{"uri":"head data.bin","byteLength""#,
        );
        assert!(json.contains("head data.bin"), "buffer entry not found");
        let dir = temp_dir("lps");
        std::fs::write(dir.join("head data.bin"), bin).unwrap();
        let path = dir.join("head.gltf");
        std::fs::write(&path, json.replace("head data.bin", "head%20data.bin")).unwrap();
        let a = load_mesh(&path, Some(50.3)).unwrap();
        let b = load_mesh(&glb, Some(50.3)).unwrap();
        assert_eq!(a.positions, b.positions);
        assert_eq!(a.indices, b.indices);
        assert_eq!(a.tangents, b.tangents);

        std::fs::remove_file(dir.join("head data.bin")).unwrap();
        let msg = load_mesh(&path, Some(50.3)).unwrap_err().to_string();
        assert!(
            msg.contains("head.gltf") && msg.contains("head data.bin"),
            "{msg}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn hand_made_gltf_external_embedded_and_glb_agree() {
        let dir = temp_dir("square");
        let doc = square();
        let path = doc.write_gltf(&dir, "square");
        let external = load_mesh(&path, Some(10.0)).unwrap();
        // Embedded base64 buffer.
        let (json, bin) = doc.build();
        let b64 = base64_encode(&bin);
        let embedded_path = dir.join("embedded.gltf");
        std::fs::write(
            &embedded_path,
            json.replace(
                "@URI@",
                &format!(r#""uri":"data:application/octet-stream;base64,{b64}","#),
            ),
        )
        .unwrap();
        let embedded = load_mesh(&embedded_path, Some(10.0)).unwrap();
        let binary = load(&doc, Some(10.0)).unwrap();
        for m in [&embedded, &binary] {
            assert_eq!(m.positions, external.positions);
            assert_eq!(m.indices, external.indices);
            assert_eq!(m.uvs, external.uvs);
        }
        assert_eq!(external.positions[2], Vec3::new(10.0, 10.0, 0.0));
        assert_eq!(external.vertex_count(), 4);
        assert_eq!(external.triangle_count(), 2);

        std::fs::remove_file(dir.join("square.bin")).unwrap();
        let msg = load_mesh(&path, None).unwrap_err().to_string();
        assert!(
            msg.contains("square.gltf") && msg.contains("'square.bin'"),
            "{msg}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    fn base64_encode(data: &[u8]) -> String {
        const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut s = String::new();
        for chunk in data.chunks(3) {
            let b = [
                chunk[0],
                *chunk.get(1).unwrap_or(&0),
                *chunk.get(2).unwrap_or(&0),
            ];
            let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
            for k in 0..4 {
                if k <= chunk.len() {
                    s.push(A[((n >> (18 - 6 * k)) & 63) as usize] as char);
                } else {
                    s.push('=');
                }
            }
        }
        s
    }

    #[test]
    fn base64_and_percent_decoding() {
        for data in [&b""[..], b"a", b"ab", b"abc", b"abcd", &[0, 255, 128, 7, 9]] {
            assert_eq!(decode_base64(&base64_encode(data)).unwrap(), data);
        }
        assert_eq!(decode_base64("a*b"), None);
        assert_eq!(percent_decode("a%20b.bin").unwrap(), "a b.bin");
        assert_eq!(percent_decode("a%2"), None);
        assert_eq!(percent_decode("%FF"), None);
    }

    #[test]
    fn tangents_follow_uv_directions() {
        // u along +X, v (down) along -Y: t = +X, bitangent = +Y = n × t → w = +1.
        let m = load(&square(), Some(1.0)).unwrap();
        for t in &m.tangents {
            assert!((t.truncate() - Vec3::X).length() < 1e-5, "{t}");
            assert_eq!(t.w, 1.0);
        }
        // Mirrored in u: t = -X and w = -1 so the bitangent still points to +Y.
        let mut mirrored = square();
        mirrored.uvs = Some(vec![[1., 1.], [0., 1.], [0., 0.], [1., 0.]]);
        let m = load(&mirrored, Some(1.0)).unwrap();
        for t in &m.tangents {
            assert!((t.truncate() + Vec3::X).length() < 1e-5, "{t}");
            assert_eq!(t.w, -1.0);
        }
        assert_eq!(uv_agreement(&m), 1.0);
        // Given tangents are used as they are.
        let mut given = square();
        given.tangents = Some(vec![[0., 1., 0., -1.]; 4]);
        let m = load(&given, Some(1.0)).unwrap();
        assert!(m.tangents.iter().all(|t| *t == Vec4::new(0., 1., 0., -1.)));
    }

    #[test]
    fn mirrored_uv_islands_split_shared_vertices() {
        // Two triangles share an edge but their UVs mirror across it.
        let doc = Doc {
            positions: vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [-1., 0., 0.]],
            normals: Some(vec![[0., 0., 1.]; 4]),
            uvs: Some(vec![[0., 1.], [1., 1.], [0., 0.], [1., 1.]]),
            indices: Some((5121, vec![0, 1, 2, 0, 2, 3])),
            ..Doc::default()
        };
        let m = load(&doc, Some(1.0)).unwrap();
        assert_eq!(m.vertex_count(), 6, "vertices 0 and 2 need one copy each");
        assert_unit_frames(&m);
        assert_eq!(uv_agreement(&m), 1.0);
    }

    #[test]
    fn missing_texcoords_is_an_error() {
        let mut doc = square();
        doc.uvs = None;
        let msg = load(&doc, None).unwrap_err().to_string();
        assert!(
            msg.starts_with("test.glb: ") && msg.contains("TEXCOORD_0"),
            "{msg}"
        );
    }

    #[test]
    fn missing_normals_are_generated() {
        // Plane tilted about X: analytic normal = normalize(e1 × e2).
        let mut plane = square();
        plane.normals = None;
        plane.positions = vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 1.], [0., 1., 1.]];
        let m = load(&plane, Some(1.0)).unwrap();
        let want = Vec3::new(0.0, -1.0, 1.0).normalize();
        for n in &m.normals {
            assert!((*n - want).length() < 1e-6, "{n}");
        }
        assert_unit_frames(&m);

        // Regular tetrahedron centred at the origin, one vertex copy per face
        // corner (as UV seams split them): smooth normal = direction of the vertex.
        let c = [[1., 1., 1.], [1., -1., -1.], [-1., 1., -1.], [-1., -1., 1.]];
        let faces = [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]];
        let mut positions = Vec::new();
        let mut uvs = Vec::new();
        for f in faces {
            for (k, &v) in f.iter().enumerate() {
                positions.push(c[v]);
                uvs.push([[0., 0.], [1., 0.], [0., 1.]][k]);
            }
        }
        let tet = Doc {
            positions,
            uvs: Some(uvs),
            ..Doc::default()
        };
        let m = load(&tet, Some(1.0)).unwrap();
        assert_eq!(m.triangle_count(), 4);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!((*n - p.normalize()).length() < 1e-5, "{p}: {n}");
        }
        // Each face's winding faces outward.
        for tri in m.indices.chunks_exact(3) {
            let f = face_cross(&m.positions, tri);
            assert!(f.dot(m.positions[tri[0] as usize]) > 0.0);
        }
        assert_unit_frames(&m);
    }

    #[test]
    fn node_transforms_apply() {
        // Parent translates (1, 2, 3) and scales 2; child translates (0, 0, 1).
        let mut doc = square();
        doc.nodes = Some((
            r#"[{"translation":[1,2,3],"scale":[2,2,2],"children":[1]},
                {"translation":[0,0,1],"mesh":0}]"#
                .into(),
            "[0]".into(),
        ));
        let m = load(&doc, Some(10.0)).unwrap();
        for (got, p) in m.positions.iter().zip(&square().positions) {
            let want = (Vec3::new(1., 2., 3.) + 2.0 * (Vec3::from(*p) + Vec3::Z)) * 10.0;
            assert!((*got - want).length() < 1e-4, "{got} vs {want}");
        }

        // Rotation 90° about Y (quaternion (0, sin45, 0, cos45)): +Z normal -> +X.
        let s = std::f32::consts::FRAC_1_SQRT_2;
        doc.nodes = Some((
            format!(r#"[{{"rotation":[0,{s},0,{s}],"scale":[1,3,1],"mesh":0}}]"#),
            "[0]".into(),
        ));
        let m = load(&doc, Some(1.0)).unwrap();
        for n in &m.normals {
            assert!((*n - Vec3::X).length() < 1e-5, "{n}");
        }
        assert_unit_frames(&m);

        // A mirror (scale -1 in X) flips the winding and the bitangent sign, so
        // the triangles still face along their normals and the frame still
        // follows the UVs.
        doc.nodes = Some((r#"[{"scale":[-1,1,1],"mesh":0}]"#.into(), "[0]".into()));
        doc.tangents = Some(vec![[1., 0., 0., 1.]; 4]);
        let m = load(&doc, Some(1.0)).unwrap();
        for tri in m.indices.chunks_exact(3) {
            assert!(face_cross(&m.positions, tri).dot(m.normals[tri[0] as usize]) > 0.0);
        }
        assert!(m.tangents.iter().all(|t| t.w == -1.0));
        assert_eq!(uv_agreement(&m), 1.0);
        doc.tangents = None;
        let m2 = load(&doc, Some(1.0)).unwrap();
        assert_eq!(
            m2.tangents, m.tangents,
            "MikkTSpace agrees with the given frame"
        );

        // Only nodes of the default scene count.
        doc.nodes = Some((
            r#"[{"mesh":0},{"mesh":0,"translation":[5,0,0]}]"#.into(),
            "[1]".into(),
        ));
        let m = load(&doc, Some(1.0)).unwrap();
        assert_eq!(m.positions[0], Vec3::new(5.0, 0.0, 0.0));
        assert_eq!(m.vertex_count(), 4);

        // Two instances merge with offset indices.
        doc.nodes = Some((
            r#"[{"mesh":0},{"mesh":0,"translation":[5,0,0]}]"#.into(),
            "[0,1]".into(),
        ));
        let m = load(&doc, Some(1.0)).unwrap();
        assert_eq!(m.vertex_count(), 8);
        assert_eq!(m.triangle_count(), 4);
        assert_eq!(m.indices[6..], [4, 5, 6, 4, 6, 7]);
    }

    #[test]
    fn sparse_accessors_substitute_values() {
        // Replace vertex 2 of the square by (1, 1, 5) through a sparse POSITION
        // accessor: one u8 index and one VEC3 value in two extra views.
        let (json, mut bin) = square().build();
        let idx_offset = bin.len();
        bin.extend([2u8, 0, 0, 0]);
        let val_offset = bin.len();
        for f in [1.0f32, 1.0, 5.0] {
            bin.extend(f.to_le_bytes());
        }
        let views_end = json
            .find(
                r#"}],
"accessors""#,
            )
            .unwrap()
            + 1;
        let mut json = format!(
            r#"{},{{"buffer":0,"byteOffset":{idx_offset},"byteLength":1}},{{"buffer":0,"byteOffset":{val_offset},"byteLength":12}}{}"#,
            &json[..views_end],
            &json[views_end..]
        );
        let view_count = json.matches(r#""buffer":0"#).count();
        let sparse = format!(
            r#","sparse":{{"count":1,"indices":{{"bufferView":{},"componentType":5121}},"values":{{"bufferView":{}}}}}"#,
            view_count - 2,
            view_count - 1
        );
        json = json.replacen(r#""type":"VEC3""#, &format!(r#""type":"VEC3"{sparse}"#), 1);
        // The buffer grew: update its declared length.
        let json = json.replace(
            &format!(r#""byteLength":{}}}"#, idx_offset),
            &format!(r#""byteLength":{}}}"#, bin.len()),
        );
        let m = load_mesh_from_slice(
            &glb(json.replace("@URI@", "").as_bytes(), &bin),
            Path::new("sparse.glb"),
            Some(1.0),
        )
        .unwrap();
        assert_eq!(m.positions[2], Vec3::new(1.0, 1.0, 5.0));
        assert_eq!(m.positions[1], Vec3::new(1.0, 0.0, 0.0));
    }

    #[test]
    fn index_types_and_non_indexed() {
        let base = load(&square(), Some(1.0)).unwrap();
        for comp in [5121, 5123, 5125] {
            let mut doc = square();
            doc.indices = Some((comp, vec![0, 1, 2, 0, 2, 3]));
            let m = load(&doc, Some(1.0)).unwrap();
            assert_eq!(m.indices, base.indices, "component type {comp}");
        }
        let mut doc = square();
        doc.positions = vec![
            [0., 0., 0.],
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 0., 0.],
            [1., 1., 0.],
            [0., 1., 0.],
        ];
        doc.normals = Some(vec![[0., 0., 1.]; 6]);
        doc.uvs = Some(vec![
            [0., 1.],
            [1., 1.],
            [1., 0.],
            [0., 1.],
            [1., 0.],
            [0., 0.],
        ]);
        doc.indices = None;
        let m = load(&doc, Some(1.0)).unwrap();
        assert_eq!(m.indices, [0, 1, 2, 3, 4, 5]);
    }

    #[test]
    fn non_triangle_primitives_are_skipped() {
        let mut doc = square();
        doc.mode = Some(0); // POINTS
        let msg = load(&doc, None).unwrap_err().to_string();
        assert!(msg.contains("no triangle primitives"), "{msg}");
        // A points primitive next to a triangle primitive: only triangles load.
        let (json, bin) = square().build();
        let json = json.replace(
            r#""primitives":[{"#,
            r#""primitives":[{"attributes":{"POSITION":0},"mode":0},{"#,
        );
        let m = load_mesh_from_slice(
            &glb(json.replace("@URI@", "").as_bytes(), &bin),
            Path::new("x.glb"),
            None,
        )
        .unwrap();
        assert_eq!(m.triangle_count(), 2);
    }

    #[test]
    fn bad_data_gives_errors() {
        let cases: Vec<(Doc, &str)> = vec![
            (
                Doc {
                    indices: Some((5123, vec![0, 1, 2, 0, 2, 9])),
                    ..square()
                },
                "only 4 vertices",
            ),
            (
                Doc {
                    indices: Some((5123, vec![0, 1, 2, 0])),
                    ..square()
                },
                "whole triangles",
            ),
            (
                Doc {
                    positions: vec![[0., 0., 0.], [f32::NAN, 0., 0.], [1., 1., 0.], [0., 1., 0.]],
                    ..square()
                },
                "POSITION of vertex 1",
            ),
            (
                Doc {
                    uvs: Some(vec![[0., 0.], [0., f32::INFINITY], [1., 0.], [0., 0.]]),
                    ..square()
                },
                "TEXCOORD_0 of vertex 1",
            ),
            (
                Doc {
                    positions: vec![[1., 1., 1.]; 4],
                    ..square()
                },
                "degenerate",
            ),
            (
                Doc {
                    uvs: Some(vec![[0., 0.]; 3]),
                    ..square()
                },
                "TEXCOORD_0 has 3",
            ),
            (
                Doc {
                    uvs: Some(vec![[0.5, 0.5]; 4]),
                    ..square()
                },
                "TEXCOORD_0 covers no texels",
            ),
            (
                Doc {
                    uvs: Some(vec![[0., 0.], [1e-4, 0.], [1e-4, 1e-4], [0., 1e-4]]),
                    ..square()
                },
                "TEXCOORD_0 covers no texels",
            ),
            (
                Doc {
                    nodes: Some((r#"[{"scale":[0,1,1],"mesh":0}]"#.into(), "[0]".into())),
                    ..square()
                },
                "singular",
            ),
        ];
        for (doc, needle) in cases {
            let msg = load(&doc, Some(1.0)).unwrap_err().to_string();
            assert!(
                msg.starts_with("test.glb: ") && msg.contains(needle),
                "{needle}: {msg}"
            );
        }
        assert!(load(&square(), Some(0.0)).is_err());
        assert!(load(&square(), Some(f32::NAN)).is_err());

        // Node cycle: 0 -> 1 -> 0.
        let (json, bin) = square().build();
        let json = json.replace(
            r#""nodes":[{"mesh":0}]"#,
            r#""nodes":[{"mesh":0,"children":[1]},{"children":[0]}]"#,
        );
        let r = load_mesh_from_slice(
            &glb(json.replace("@URI@", "").as_bytes(), &bin),
            Path::new("c.glb"),
            None,
        );
        assert!(r.is_err());

        // Accessor reading past the end of its view.
        let (json, bin) = square().build();
        let json = json.replacen(r#""count":4"#, r#""count":40"#, 1);
        let msg = load_mesh_from_slice(
            &glb(json.replace("@URI@", "").as_bytes(), &bin),
            Path::new("o.glb"),
            None,
        )
        .unwrap_err()
        .to_string();
        assert!(msg.starts_with("o.glb: "), "{msg}");
    }

    #[test]
    fn corrupt_files_give_errors_naming_the_file() {
        let dir = temp_dir("corrupt");
        let good = square().glb();
        let mut cases: Vec<(String, Vec<u8>)> = vec![
            ("empty.glb".into(), Vec::new()),
            ("garbage.glb".into(), b"not a gltf at all".to_vec()),
            (
                "bad-json.gltf".into(),
                br#"{"asset": {"version": "2.0"}, "meshes": [}"#.to_vec(),
            ),
            (
                "wrong-json.gltf".into(),
                br#"{"asset": {"version": "2.0"}, "meshes": 5}"#.to_vec(),
            ),
            (
                "no-mesh.gltf".into(),
                br#"{"asset": {"version": "2.0"}}"#.to_vec(),
            ),
        ];
        for cut in [4, 12, 20, 40, good.len() / 2, good.len() - 1] {
            cases.push((format!("cut-{cut}.glb"), good[..cut].to_vec()));
        }
        let bytes = std::fs::read(lee_perry_smith()).unwrap();
        for cut in [11, 100, 1000, 1935, 5000, bytes.len() / 2, bytes.len() - 4] {
            cases.push((format!("lps-cut-{cut}.glb"), bytes[..cut].to_vec()));
        }
        for (name, bytes) in cases {
            let path = dir.join(&name);
            std::fs::write(&path, &bytes).unwrap();
            let msg = match load_mesh(&path, Some(1.0)) {
                Ok(_) => panic!("{name} loaded"),
                Err(e) => e.to_string(),
            };
            assert!(msg.contains(&name) && !msg.contains('\n'), "{msg}");
        }
        let msg = load_mesh(&dir.join("absent.glb"), None)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("absent.glb"), "{msg}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn fuzzed_glb_never_panics() {
        let lps = lee_perry_smith();
        let bytes = std::fs::read(lps).unwrap();
        let json_end =
            20 + u32::from_le_bytes([bytes[12], bytes[13], bytes[14], bytes[15]]) as usize;
        let mut rng = 0x1234_5678_9ABC_DEF1u64;
        let mut next = move || {
            // xorshift64* (Vigna 2016)
            rng ^= rng >> 12;
            rng ^= rng << 25;
            rng ^= rng >> 27;
            rng.wrapping_mul(0x2545_F491_4F6C_DD1D)
        };
        let (mut ok, mut rejected) = (0, 0);
        let start = std::time::Instant::now();
        for i in 0..300 {
            let mut b = bytes.clone();
            match i % 3 {
                0 => b.truncate((next() as usize) % bytes.len()),
                // Flips in the header and JSON, where structure lives.
                1 => {
                    for _ in 0..1 + next() % 3 {
                        let at = (next() as usize) % json_end;
                        b[at] ^= 1 << (next() % 8);
                    }
                }
                _ => {
                    for _ in 0..1 + next() % 16 {
                        let at = (next() as usize) % b.len();
                        b[at] ^= 1 << (next() % 8);
                    }
                }
            }
            let outcome = std::panic::catch_unwind(|| {
                load_mesh_from_slice(&b, Path::new("fuzz.glb"), Some(50.3))
            });
            match outcome {
                Ok(Ok(mesh)) => {
                    mesh.validate().unwrap();
                    ok += 1
                }
                Ok(Err(e)) => {
                    let msg = e.to_string();
                    assert!(
                        msg.starts_with("fuzz.glb: ") && !msg.contains('\n'),
                        "{msg}"
                    );
                    rejected += 1
                }
                Err(_) => panic!("loader panicked on case {i}"),
            }
        }
        println!(
            "fuzzed glb: {ok} loaded, {rejected} rejected in {:?}",
            start.elapsed()
        );
        assert!(rejected >= 100, "every truncation must be rejected");
    }
}
