//! The truth beside a frame as files: a 16-bit depth PNG in millimetres, a label PNG with a
//! palette, and the labels' legend as JSON; and reading them back.
//!
//! - `*_depth.png`: 16-bit grey, the depth in mm rounded ([`TruthFrame::depth_mm`]); 0 where
//!   unknown (the sky, no mirror), 65535 at and beyond 65.535 m.
//! - `*_labels.png`: 8-bit indexed, each pixel its label number, the palette the legend's
//!   colours (16-bit grey where a world has more than 256 labels).
//! - `legend.json`: `[{label, class, instance, name, rgb}, ...]` in label order.

use omniloop_sim::render::TruthFrame;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// A truth file that could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum TruthFileError {
    /// Writing or reading the file failed.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why (in the message, not a separate cause).
        reason: std::io::Error,
    },
    /// Encoding or decoding the PNG failed.
    #[error("{path}: {why}")]
    Png {
        /// The file.
        path: PathBuf,
        /// Why.
        why: String,
    },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> TruthFileError + '_ {
    move |reason| TruthFileError::Io {
        path: path.to_path_buf(),
        reason,
    }
}

fn png_err(path: &Path) -> impl FnOnce(png::EncodingError) -> TruthFileError + '_ {
    move |e| TruthFileError::Png {
        path: path.to_path_buf(),
        why: e.to_string(),
    }
}

/// The depth in whole millimetres as the depth PNG stores it: 0 where unknown or infinite,
/// saturating at 65535.
pub fn depth_level(depth_mm: f32) -> u16 {
    if depth_mm.is_finite() && depth_mm > 0.0 {
        depth_mm.round().min(65535.0) as u16
    } else {
        0
    }
}

/// Writes one PNG of `width x height` in `colour`/`depth` with `data` (big-endian for 16 bits),
/// with `palette` where given.
fn write_png(
    path: &Path,
    size: [u32; 2],
    kind: (png::ColorType, png::BitDepth),
    palette: Option<Vec<u8>>,
    data: &[u8],
) -> Result<(), TruthFileError> {
    let file = std::fs::File::create(path).map_err(io(path))?;
    let mut enc = png::Encoder::new(BufWriter::new(file), size[0], size[1]);
    enc.set_color(kind.0);
    enc.set_depth(kind.1);
    if let Some(p) = palette {
        enc.set_palette(p);
    }
    let mut w = enc.write_header().map_err(png_err(path))?;
    w.write_image_data(data).map_err(png_err(path))?;
    w.finish().map_err(png_err(path))
}

/// Writes the depth PNG.
pub fn write_depth_png(path: &Path, truth: &TruthFrame) -> Result<(), TruthFileError> {
    let data: Vec<u8> = (truth.depth_mm.iter())
        .flat_map(|&d| depth_level(d).to_be_bytes())
        .collect();
    let kind = (png::ColorType::Grayscale, png::BitDepth::Sixteen);
    write_png(path, [truth.width, truth.height], kind, None, &data)
}

/// Writes the label PNG: indexed with the legend's colours as its palette, or 16-bit grey
/// where there are more than 256 labels.
pub fn write_label_png(path: &Path, truth: &TruthFrame) -> Result<(), TruthFileError> {
    let size = [truth.width, truth.height];
    let entries = truth.legend.entries();
    if entries.len() > 256 {
        let data: Vec<u8> = truth.labels.iter().flat_map(|l| l.to_be_bytes()).collect();
        let kind = (png::ColorType::Grayscale, png::BitDepth::Sixteen);
        return write_png(path, size, kind, None, &data);
    }
    let palette: Vec<u8> = entries.iter().flat_map(|e| e.rgb).collect();
    let data: Vec<u8> = truth.labels.iter().map(|&l| l as u8).collect();
    let kind = (png::ColorType::Indexed, png::BitDepth::Eight);
    write_png(path, size, kind, Some(palette), &data)
}

/// Writes the legend as JSON.
pub fn write_legend(path: &Path, truth: &TruthFrame) -> Result<(), TruthFileError> {
    // Plain records of numbers and strings always serialise.
    let text = serde_json::to_string_pretty(&truth.legend.entries()).unwrap_or_default();
    std::fs::write(path, text + "\n").map_err(io(path))
}

/// Writes `<stem>_depth.png` and `<stem>_labels.png` beside each other in `dir`.
pub fn write_truth(dir: &Path, stem: &str, truth: &TruthFrame) -> Result<(), TruthFileError> {
    write_depth_png(&dir.join(format!("{stem}_depth.png")), truth)?;
    write_label_png(&dir.join(format!("{stem}_labels.png")), truth)
}

/// A PNG read back as it is stored: its size and one value a pixel (a grey level, 8 or 16
/// bits, or a palette index; the first channel of a colour image).
#[derive(Debug, Clone, PartialEq)]
pub struct Levels {
    /// Width, px.
    pub width: u32,
    /// Height, px.
    pub height: u32,
    /// One value a pixel, row-major.
    pub values: Vec<u16>,
}

/// Reads a depth or label PNG as [`Levels`] (palette indices, not colours).
pub fn read_levels(path: &Path) -> Result<Levels, TruthFileError> {
    let bad = |why: String| TruthFileError::Png {
        path: path.to_path_buf(),
        why,
    };
    let file = std::fs::File::open(path).map_err(io(path))?;
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    // Palette indices and 16-bit levels as stored, not expanded.
    decoder.set_transformations(png::Transformations::IDENTITY);
    let mut reader = decoder.read_info().map_err(|e| bad(e.to_string()))?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| bad("image too large".into()))?;
    let mut buf = vec![0; size];
    let info = reader
        .next_frame(&mut buf)
        .map_err(|e| bad(e.to_string()))?;
    let channels = info.color_type.samples();
    let values: Vec<u16> = match info.bit_depth {
        png::BitDepth::Eight => buf[..info.buffer_size()]
            .chunks_exact(channels)
            .map(|c| u16::from(c[0]))
            .collect(),
        png::BitDepth::Sixteen => buf[..info.buffer_size()]
            .chunks_exact(2 * channels)
            .map(|c| u16::from_be_bytes([c[0], c[1]]))
            .collect(),
        other => return Err(bad(format!("unsupported bit depth {other:?}"))),
    };
    Ok(Levels {
        width: info.width,
        height: info.height,
        values,
    })
}
