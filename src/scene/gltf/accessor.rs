//! Accessor decoding with checked arithmetic: malformed offsets, strides and
//! counts give an error instead of a panic (the gltf crate's readers assume
//! valid files).

use gltf::accessor::{DataType, Dimensions};

use super::{MAX_ELEMENTS, MAX_VIEWLESS_ELEMENTS};

pub(super) fn component_size(t: DataType) -> usize {
    match t {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::U32 | DataType::F32 => 4,
    }
}

pub(super) fn component_count(d: Dimensions) -> usize {
    match d {
        Dimensions::Scalar => 1,
        Dimensions::Vec2 => 2,
        Dimensions::Vec3 => 3,
        Dimensions::Vec4 | Dimensions::Mat2 => 4,
        Dimensions::Mat3 => 9,
        Dimensions::Mat4 => 16,
    }
}

/// Bytes of a buffer view.
pub(super) fn view_bytes<'b>(
    view: &gltf::buffer::View,
    buffers: &'b [Vec<u8>],
) -> Result<&'b [u8], String> {
    let range = view.offset()..view.offset().saturating_add(view.length());
    buffers
        .get(view.buffer().index())
        .and_then(|b| b.get(range))
        .ok_or(format!(
            "buffer view {} lies outside its buffer",
            view.index()
        ))
}

/// The accessor's elements packed tightly (`count * element size` bytes), with
/// sparse substitutions applied (glTF 2.0 §3.6.2.3).
pub(super) fn packed_elements(
    acc: &gltf::Accessor,
    buffers: &[Vec<u8>],
) -> Result<Vec<u8>, String> {
    let id = acc.index();
    let count = acc.count();
    let elem = component_size(acc.data_type()) * component_count(acc.dimensions());
    if count > MAX_ELEMENTS {
        return Err(format!(
            "accessor {id} has {count} elements (limit {MAX_ELEMENTS})"
        ));
    }
    let outside = || format!("accessor {id} reads outside its buffer view");
    let mut out = match acc.view() {
        Some(view) => {
            let data = view_bytes(&view, buffers)?;
            let stride = view.stride().unwrap_or(elem);
            if stride < elem {
                return Err(format!(
                    "accessor {id}: byte stride {stride} < element size {elem}"
                ));
            }
            let mut out = Vec::with_capacity(count * elem);
            for i in 0..count {
                let start = i
                    .checked_mul(stride)
                    .and_then(|s| s.checked_add(acc.offset()))
                    .ok_or_else(outside)?;
                let end = start.checked_add(elem).ok_or_else(outside)?;
                out.extend_from_slice(data.get(start..end).ok_or_else(outside)?);
            }
            out
        }
        None if count > MAX_VIEWLESS_ELEMENTS => {
            return Err(format!(
                "accessor {id} has no buffer view but {count} elements (limit \
                 {MAX_VIEWLESS_ELEMENTS})"
            ))
        }
        None => vec![0u8; count * elem],
    };
    if let Some(sparse) = acc.sparse() {
        let n = sparse.count();
        let idx = sparse.indices();
        let idx_size = idx.index_type().size();
        let idx_data = view_bytes(&idx.view(), buffers)?;
        let val_data = view_bytes(&sparse.values().view(), buffers)?;
        let bad = || format!("accessor {id}: sparse data out of range");
        for k in 0..n.min(MAX_ELEMENTS) {
            let at = k
                .checked_mul(idx_size)
                .and_then(|o| o.checked_add(idx.offset()))
                .ok_or_else(bad)?;
            let raw = idx_data.get(at..at + idx_size).ok_or_else(bad)?;
            let target = raw
                .iter()
                .rev()
                .fold(0usize, |a, &b| (a << 8) | usize::from(b));
            let from = k
                .checked_mul(elem)
                .and_then(|o| o.checked_add(sparse.values().offset()))
                .ok_or_else(bad)?;
            let value = val_data.get(from..from + elem).ok_or_else(bad)?;
            let to = target.checked_mul(elem).ok_or_else(bad)?;
            let slot = out.get_mut(to..to + elem).ok_or_else(bad)?;
            slot.copy_from_slice(value);
        }
    }
    Ok(out)
}

/// Reads `N`-component float elements; integer types are normalised when the
/// accessor says so (glTF 2.0 §3.11, "Animations"/"Meshes" normalisation table).
pub(super) fn read_floats<const N: usize>(
    acc: &gltf::Accessor,
    buffers: &[Vec<u8>],
    semantic: &str,
) -> Result<Vec<[f32; N]>, String> {
    let dims = component_count(acc.dimensions());
    if dims != N {
        return Err(format!(
            "{semantic} accessor {} has {dims} components per element, expected {N}",
            acc.index()
        ));
    }
    let (t, norm) = (acc.data_type(), acc.normalized());
    let size = component_size(t);
    let packed = packed_elements(acc, buffers)?;
    let values: Vec<f32> = packed
        .chunks_exact(size)
        .map(|c| decode_float(c, t, norm))
        .collect();
    Ok(values
        .chunks_exact(N)
        .map(|c| {
            let mut a = [0.0; N];
            for (dst, src) in a.iter_mut().zip(c) {
                *dst = *src;
            }
            a
        })
        .collect())
}

pub(super) fn decode_float(c: &[u8], t: DataType, normalized: bool) -> f32 {
    let b = |i: usize| c.get(i).copied().unwrap_or(0);
    match (t, normalized) {
        (DataType::F32, _) => f32::from_le_bytes([b(0), b(1), b(2), b(3)]),
        (DataType::U8, false) => f32::from(b(0)),
        (DataType::U8, true) => f32::from(b(0)) / 255.0,
        (DataType::I8, false) => f32::from(b(0) as i8),
        (DataType::I8, true) => (f32::from(b(0) as i8) / 127.0).max(-1.0),
        (DataType::U16, false) => f32::from(u16::from_le_bytes([b(0), b(1)])),
        (DataType::U16, true) => f32::from(u16::from_le_bytes([b(0), b(1)])) / 65535.0,
        (DataType::I16, false) => f32::from(i16::from_le_bytes([b(0), b(1)])),
        (DataType::I16, true) => (f32::from(i16::from_le_bytes([b(0), b(1)])) / 32767.0).max(-1.0),
        (DataType::U32, _) => u32::from_le_bytes([b(0), b(1), b(2), b(3)]) as f32,
    }
}

/// Reads an index accessor (scalar u8, u16 or u32; glTF 2.0 §3.7.2.1).
pub(super) fn read_indices(acc: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<u32>, String> {
    let t = acc.data_type();
    if acc.dimensions() != Dimensions::Scalar
        || !matches!(t, DataType::U8 | DataType::U16 | DataType::U32)
    {
        return Err(format!(
            "index accessor {} must be scalar u8, u16 or u32, not {:?} {:?}",
            acc.index(),
            acc.dimensions(),
            t
        ));
    }
    let packed = packed_elements(acc, buffers)?;
    Ok(packed
        .chunks_exact(component_size(t))
        .map(|c| c.iter().rev().fold(0u32, |a, &b| (a << 8) | u32::from(b)))
        .collect())
}

// ---------------------------------------------------------------------------
// Primitives
