//! The error of an image against a reference over the face: RMSE and maximum of
//! the absolute difference relative to the reference's mean, its 99th percentile,
//! and PSNR against the reference's peak, over the RGB channels of the pixels a
//! mask keeps (the mesh's coverage: alpha > 0.5 with `render.skybox = false`);
//! and per-pixel relative errors of luminance (mean, median, 90th percentile).

use crate::error::{Error, Result};
use crate::scene::texture::LUMINANCE;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImageError {
    /// √(mean (a − r)²) / mean(r), over masked pixels and RGB.
    pub rmse_rel: f64,
    /// max |a − r| / mean(r).
    pub max_rel: f64,
    /// 99th percentile of |a − r| / mean(r).
    pub p99_rel: f64,
    /// 20·log10(max r / RMSE); `None` for identical images.
    pub psnr_db: Option<f64>,
    /// Pixels compared.
    pub pixels: usize,
}

/// Pixels whose alpha (RGBA, row-major) exceeds one half.
pub fn coverage_mask(rgba: &[f32]) -> Vec<bool> {
    rgba.chunks_exact(4).map(|p| p[3] > 0.5).collect()
}

/// The (reference, image) RGBA pixels `mask` keeps; `what` names the metric in
/// the error for images of different sizes.
fn masked<'a>(
    what: &str,
    reference: &'a [f32],
    image: &'a [f32],
    mask: &'a [bool],
) -> Result<impl Iterator<Item = (&'a [f32], &'a [f32])>> {
    if reference.len() != image.len() || reference.len() != 4 * mask.len() {
        return Err(Error::Input(format!(
            "{what}: sizes differ ({} and {} values, mask of {} pixels)",
            reference.len(),
            image.len(),
            mask.len()
        )));
    }
    Ok(reference
        .chunks_exact(4)
        .zip(image.chunks_exact(4))
        .zip(mask)
        .filter(|(_, &m)| m)
        .map(|(pair, _)| pair))
}

/// `image` against `reference` (both RGBA f32 of the same size) over `mask`.
pub fn compare(reference: &[f32], image: &[f32], mask: &[bool]) -> Result<ImageError> {
    let pairs: Vec<(f64, f64)> = masked("image error", reference, image, mask)?
        .flat_map(|(r, a)| (0..3).map(move |c| (r[c] as f64, a[c] as f64)))
        .collect();
    let pixels = pairs.len() / 3;
    let mean = pairs.iter().map(|p| p.0).sum::<f64>() / pairs.len().max(1) as f64;
    if pixels == 0 || mean <= 0.0 || !mean.is_finite() {
        return Err(Error::Input(format!(
            "image error: no covered pixels with a positive mean ({pixels} pixels, mean {mean})"
        )));
    }
    let peak = pairs.iter().map(|p| p.0).fold(0.0, f64::max);
    let mut diff: Vec<f64> = pairs.iter().map(|(r, a)| (a - r).abs()).collect();
    let rmse = (diff.iter().map(|d| d * d).sum::<f64>() / diff.len() as f64).sqrt();
    diff.sort_by(f64::total_cmp);
    let p99 = diff[((diff.len() - 1) as f64 * 0.99).round() as usize];
    Ok(ImageError {
        rmse_rel: rmse / mean,
        max_rel: diff.last().copied().unwrap_or(0.0) / mean,
        p99_rel: p99 / mean,
        psnr_db: (rmse > 0.0).then(|| 20.0 * (peak / rmse).log10()),
        pixels,
    })
}

/// Per-pixel relative error of an image's luminance against a reference's, over
/// a mask: |a − r| / max(r, floor), floor = [`RELATIVE_FLOOR`] × the mean
/// reference luminance, so deep shadows (r → 0) do not divide by nothing: a
/// pixel darker than a tenth of the mean is judged against that tenth, as
/// relative-MSE metrics add an ε of a few % of the image's level (Rousselle et
/// al. 2011 use 0.01 on images of mean ~0.2–0.5).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RelativeError {
    pub mean: f64,
    pub median: f64,
    pub p90: f64,
    /// Share of pixels within 5 %.
    pub within_5_percent: f64,
    pub pixels: usize,
}

/// The floor of [`RelativeError`]'s denominator, as a share of the mean.
pub const RELATIVE_FLOOR: f64 = 0.1;

/// Rec. 709 luminance of an RGBA pixel.
fn luminance(p: &[f32]) -> f64 {
    glam::Vec3::from_slice(&p[..3])
        .as_dvec3()
        .dot(LUMINANCE.as_dvec3())
}

/// [`RelativeError`] of `image` against `reference` (RGBA f32, same size) over `mask`.
pub fn relative(reference: &[f32], image: &[f32], mask: &[bool]) -> Result<RelativeError> {
    let pairs: Vec<(f64, f64)> = masked("relative error", reference, image, mask)?
        .map(|(r, a)| (luminance(r), luminance(a)))
        .collect();
    let mean = pairs.iter().map(|p| p.0).sum::<f64>() / pairs.len().max(1) as f64;
    if pairs.is_empty() || mean <= 0.0 || !mean.is_finite() {
        return Err(Error::Input(format!(
            "relative error: no covered pixels with a positive mean ({} pixels, mean {mean})",
            pairs.len()
        )));
    }
    let floor = RELATIVE_FLOOR * mean;
    let mut rel: Vec<f64> = pairs
        .iter()
        .map(|(r, a)| (a - r).abs() / r.max(floor))
        .collect();
    rel.sort_by(f64::total_cmp);
    let at = |q: f64| rel[((rel.len() - 1) as f64 * q).round() as usize];
    Ok(RelativeError {
        mean: rel.iter().sum::<f64>() / rel.len() as f64,
        median: at(0.5),
        p90: at(0.9),
        within_5_percent: rel.iter().filter(|&&e| e <= 0.05).count() as f64 / rel.len() as f64,
        pixels: rel.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A w×1 RGBA image with value `v(x)` in RGB and alpha `a(x)`.
    fn image(w: usize, v: impl Fn(usize) -> f32, a: impl Fn(usize) -> f32) -> Vec<f32> {
        (0..w).flat_map(|x| [v(x), v(x), v(x), a(x)]).collect()
    }

    #[test]
    fn identical_images_have_no_error() {
        let r = image(8, |x| x as f32 + 1.0, |_| 1.0);
        let e = compare(&r, &r, &coverage_mask(&r)).unwrap();
        assert_eq!((e.rmse_rel, e.max_rel, e.p99_rel), (0.0, 0.0, 0.0));
        assert_eq!(e.psnr_db, None);
        assert_eq!(e.pixels, 8);
    }

    #[test]
    fn a_constant_offset_gives_its_known_error() {
        // Reference values 1..=4 (mean 2.5, peak 4) plus 0.25 everywhere.
        let r = image(4, |x| x as f32 + 1.0, |_| 1.0);
        let a = image(4, |x| x as f32 + 1.25, |_| 1.0);
        let e = compare(&r, &a, &coverage_mask(&r)).unwrap();
        assert!((e.rmse_rel - 0.1).abs() < 1e-12, "{e:?}");
        assert!((e.max_rel - 0.1).abs() < 1e-12, "{e:?}");
        assert!((e.p99_rel - 0.1).abs() < 1e-12, "{e:?}");
        let psnr = 20.0 * (4.0f64 / 0.25).log10();
        assert!((e.psnr_db.unwrap() - psnr).abs() < 1e-9, "{e:?}");
    }

    #[test]
    fn uncovered_pixels_do_not_count() {
        // Pixels 2 and 3 are background (alpha 0) and differ wildly.
        let r = image(4, |_| 1.0, |x| if x < 2 { 1.0 } else { 0.0 });
        let a = image(4, |x| if x < 2 { 1.0 } else { 100.0 }, |_| 1.0);
        let e = compare(&r, &a, &coverage_mask(&r)).unwrap();
        assert_eq!((e.rmse_rel, e.pixels), (0.0, 2));
    }

    #[test]
    fn relative_errors_of_known_images() {
        // Reference 1, 2, 4, 8 (mean 3.75); the image 10 % high on the first
        // three, 30 % low on the last: mean (0.1·3 + 0.3)/4, median and p90 by rank.
        let r = image(4, |x| (1 << x) as f32, |_| 1.0);
        let a = image(
            4,
            |x| (1 << x) as f32 * if x < 3 { 1.1 } else { 0.7 },
            |_| 1.0,
        );
        let e = relative(&r, &a, &coverage_mask(&r)).unwrap();
        assert!((e.mean - 0.15).abs() < 1e-6, "{e:?}");
        assert!(
            (e.median - 0.1).abs() < 1e-6 && (e.p90 - 0.3).abs() < 1e-6,
            "{e:?}"
        );
        assert_eq!((e.within_5_percent, e.pixels), (0.0, 4));
        // A pixel black in the reference divides by the floor, 10 % of the mean.
        let r = image(2, |x| [0.0, 2.0][x], |_| 1.0);
        let a = image(2, |x| [0.01, 2.0][x], |_| 1.0);
        let e = relative(&r, &a, &coverage_mask(&r)).unwrap();
        assert!((e.mean - 0.5 * 0.01 / (0.1 * 1.0)).abs() < 1e-6, "{e:?}");
    }

    #[test]
    fn an_empty_mask_or_mismatched_sizes_are_errors() {
        let r = image(4, |_| 1.0, |_| 0.0);
        assert!(compare(&r, &r, &coverage_mask(&r)).is_err());
        let s = image(3, |_| 1.0, |_| 1.0);
        assert!(compare(&r, &s, &coverage_mask(&r)).is_err());
        assert!(relative(&r, &r, &coverage_mask(&r)).is_err());
        assert!(relative(&r, &s, &coverage_mask(&r)).is_err());
    }
}
