//! Writing a sweep's files (each through [`super::atomic`]).

use super::{csv, plot, Sweep};
use crate::atomic::write_atomic;
use crate::error::{Error, Result};
use std::path::Path;

pub fn json(sweep: &Sweep) -> Result<String> {
    serde_json::to_string_pretty(sweep).map_err(|e| Error::Input(format!("sweep.json: {e}")))
}

/// `sweep.csv` and the plots (what `--replot` redraws).
pub fn write_csv_and_plots(sweep: &Sweep, dir: &Path) -> Result<()> {
    write_atomic(&dir.join("sweep.csv"), csv(sweep))?;
    plot::write_plots(sweep, dir)
}

/// `sweep.json`, `sweep.csv` and the plots into `dir` (created).
pub fn write_all(sweep: &Sweep, dir: &Path) -> Result<()> {
    create_dir(dir)?;
    write_atomic(&dir.join("sweep.json"), &json(sweep)?)?;
    write_csv_and_plots(sweep, dir)
}

/// Creates `dir` and its parents; an error names it.
pub fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        path: dir.display().to_string(),
        source,
    })
}

/// RGBA images of one size side by side in a PNG, all at the exposure of the
/// first (given in `render`, or metered on it), as the tone map shows them.
pub fn write_side_by_side(
    path: &Path,
    (w, h): (u32, u32),
    images: &[&[f32]],
    render: &crate::scene::file::Render,
) -> Result<()> {
    use crate::post::tonemap::encode8;
    use crate::post::{meter, Exposure, PostSettings};
    let post = PostSettings::resolve(render);
    let exposure = match post.exposure {
        Exposure::Given(ev) => ev,
        Exposure::Metered => images.first().map_or(0.0, |i| meter::exposure(i).ev),
    };
    let encoded: Vec<Vec<u8>> = images
        .iter()
        .map(|i| encode8(i, exposure, &post.display))
        .collect();
    let row_bytes = 4 * w as usize;
    let side_by_side: Vec<u8> = (0..h as usize)
        .flat_map(|y| {
            encoded
                .iter()
                .flat_map(move |i| i[y * row_bytes..(y + 1) * row_bytes].to_vec())
        })
        .collect();
    crate::render::output::write_rgba8_png(path, images.len() as u32 * w, h, &side_by_side)
}
