//! One terrain map: a square RGB image over [0, 1]² whose colour sets the friction coefficient (thesis eq. 5.15)
//! and whose inverted colour is what the robot observes.

use std::path::Path;

use crate::error::{Error, Result};
use crate::util::bounded_read::read_bounded;

/// Side of a map in pixels, as the thesis' maps are (the authors resize to 500 and crop 20 pixels each side).
pub const MAP_SIZE: usize = 460;
pub const MU_MIN: f64 = 0.1;
pub const MU_MAX: f64 = 10.0;
/// A user's PNG is read only up to this many bytes and this many pixels a side.
const MAX_PNG_BYTES: u64 = 256 << 20;
const MAX_PNG_SIDE: u32 = 16_384;
const DEFLATE_MAX_RATIO: usize = 1032;

#[derive(Clone, PartialEq)]
pub struct TerrainMap {
    /// Row-major RGB, `MAP_SIZE` × `MAP_SIZE`. Row index follows the position's x, column index its y (the
    /// authors' indexing: plots of a map show its transpose).
    rgb: Vec<u8>,
    /// What datasets record to name the map (its file name, or "generated").
    pub name: String,
    /// CRC-32 of the pixels: two maps with the same name and different pixels are told apart.
    pub crc32: u32,
}

impl std::fmt::Debug for TerrainMap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "TerrainMap({}, crc32 {:08x})", self.name, self.crc32)
    }
}

/// η of eq. 5.15 for an unnormalized feature colour τ̂ = (r, g, b): the 24-bit colour as a fraction of 2²⁴ − 1.
fn eta(feature: [u8; 3]) -> f64 {
    let packed = ((feature[0] as u32) << 16) | ((feature[1] as u32) << 8) | feature[2] as u32;
    packed as f64 / ((1u32 << 24) - 1) as f64
}

/// Friction coefficient of a map pixel's colour: eq. 5.15 on the unnormalized feature τ̂ = 255 − colour.
///
/// The authors computed τ̂ as `uint(255 · (1 − colour/255))`, whose float rounding drops some channel values by
/// one (43 → 211 instead of 212); we take the exact integer, which the equation means.
pub fn friction_of_color(color: [u8; 3]) -> f64 {
    let e = eta(color.map(|c| 255 - c));
    MU_MIN + (MU_MAX - MU_MIN) * e * e
}

/// Pixel row/column of a coordinate in [0, 1] (clamped first), as the authors index: ⌊p · (size − 1)⌋.
fn pixel_index(p: f64) -> usize {
    let p = if p.is_nan() { 0.0 } else { p.clamp(0.0, 1.0) };
    ((p * (MAP_SIZE - 1) as f64) as usize).min(MAP_SIZE - 1)
}

impl TerrainMap {
    /// A map from `MAP_SIZE`² RGB pixels.
    pub fn from_rgb(rgb: Vec<u8>, name: impl Into<String>) -> Result<Self> {
        if rgb.len() != MAP_SIZE * MAP_SIZE * 3 {
            return Err(Error::data(format!(
                "a terrain map has {MAP_SIZE} × {MAP_SIZE} RGB pixels, got {} bytes",
                rgb.len()
            )));
        }
        let crc32 = crc32fast::hash(&rgb);
        Ok(TerrainMap { rgb, name: name.into(), crc32 })
    }

    pub fn rgb(&self) -> &[u8] {
        &self.rgb
    }

    pub fn color_at(&self, x: f64, y: f64) -> [u8; 3] {
        let i = (pixel_index(x) * MAP_SIZE + pixel_index(y)) * 3;
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    /// The colours at the centres of an n × n grid over [0, 1]², cell (i, j) at `3 (i n + j)`: the map coarsened
    /// for drawing (plots, the live view).
    pub fn coarse_rgb(&self, cells: usize) -> Vec<u8> {
        let centre = |k: usize| (k as f64 + 0.5) / cells as f64;
        (0..cells).flat_map(|i| (0..cells).flat_map(move |j| self.color_at(centre(i), centre(j)))).collect()
    }

    /// The observed terrain feature τ = 1 − colour/255 ∈ [0, 1]³ at a position.
    pub fn feature_at(&self, x: f64, y: f64) -> [f64; 3] {
        self.color_at(x, y).map(|c| 1.0 - c as f64 / 255.0)
    }

    /// μ ∈ [0.1, 10] at a position.
    pub fn friction_at(&self, x: f64, y: f64) -> f64 {
        friction_of_color(self.color_at(x, y))
    }

    /// Reads an 8-bit RGB (or palette) PNG of any size up to 16384², resized to 460 × 460 by nearest neighbour:
    /// blending colours would invent frictions that no patch has, since μ depends on the packed 24-bit colour.
    pub fn read_png(path: &Path) -> Result<Self> {
        let bytes = read_bounded(path, MAX_PNG_BYTES)?;
        let bad = |m: String| Error::bad_file(path, m);
        let mut decoder = png::Decoder::new_with_limits(
            std::io::Cursor::new(&bytes[..]),
            png::Limits { bytes: (MAX_PNG_SIDE as usize).pow(2) * 4 },
        );
        decoder.set_transformations(png::Transformations::EXPAND);
        let mut reader = decoder.read_info().map_err(|e| bad(format!("not a readable PNG map: {e}")))?;
        let (width, height) = (reader.info().width, reader.info().height);
        if width == 0 || height == 0 || width > MAX_PNG_SIDE || height > MAX_PNG_SIDE {
            return Err(bad(format!("map is {width} × {height} pixels; expected 1 to {MAX_PNG_SIDE} a side")));
        }
        let (color, depth) = reader.output_color_type();
        if color != png::ColorType::Rgb || depth != png::BitDepth::Eight {
            return Err(bad(format!(
                "map is {color:?} {}-bit; expected 8-bit RGB (friction is read from the 24-bit colour, so \
                 grayscale, alpha and 16-bit maps are refused rather than guessed)",
                depth as u8
            )));
        }
        let needed = reader.output_buffer_size().ok_or_else(|| bad("map too large".into()))?;
        // Deflate expands at most 1032-fold: a header that declares more pixels than the file's bytes can hold
        // is refused before its buffer is allocated.
        if needed > bytes.len().saturating_mul(DEFLATE_MAX_RATIO) {
            return Err(bad(format!(
                "declares {width} × {height} pixels, more than its {} bytes can hold",
                bytes.len()
            )));
        }
        let mut pixels = vec![0; needed];
        let frame = reader.next_frame(&mut pixels).map_err(|e| bad(format!("PNG data: {e}")))?;
        let stride = frame.line_size;
        let mut rgb = vec![0u8; MAP_SIZE * MAP_SIZE * 3];
        for row in 0..MAP_SIZE {
            let src_row = row * height as usize / MAP_SIZE;
            for col in 0..MAP_SIZE {
                let src_col = col * width as usize / MAP_SIZE;
                let s = src_row * stride + src_col * 3;
                rgb[(row * MAP_SIZE + col) * 3..][..3].copy_from_slice(&pixels[s..s + 3]);
            }
        }
        let name = path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned());
        Self::from_rgb(rgb, name)
    }

    pub fn png_bytes(&self) -> Result<Vec<u8>> {
        crate::util::png::encode_rgb(MAP_SIZE as u32, MAP_SIZE as u32, &self.rgb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn friction_follows_eq_5_15_on_the_inverted_colour() {
        // White maps to τ̂ = 0 (lowest friction), black to τ̂ = 0xFFFFFF (highest).
        assert_eq!(friction_of_color([255, 255, 255]), MU_MIN);
        assert!((friction_of_color([0, 0, 0]) - MU_MAX).abs() < 1e-12);
        // τ̂ = (127, 0, 0): η = 127·2¹⁶ / (2²⁴ − 1).
        let eta = (127u32 << 16) as f64 / 16_777_215.0;
        assert!((friction_of_color([128, 255, 255]) - (0.1 + 9.9 * eta * eta)).abs() < 1e-12);
        // Red is the high byte: green and blue together move μ less than one step of red does.
        let span = friction_of_color([200, 0, 0]) - friction_of_color([200, 255, 255]);
        assert!(span > 0.0 && span < friction_of_color([199, 255, 255]) - friction_of_color([200, 255, 255]));
    }

    #[test]
    fn positions_index_rows_by_x_and_columns_by_y() {
        let mut rgb = vec![255u8; MAP_SIZE * MAP_SIZE * 3];
        // Pixel (row 459, col 0) black: x = 1, y = 0.
        rgb[(459 * MAP_SIZE) * 3..][..3].copy_from_slice(&[0, 0, 0]);
        let map = TerrainMap::from_rgb(rgb, "t").unwrap();
        assert_eq!(map.color_at(1.0, 0.0), [0, 0, 0]);
        assert_eq!(map.color_at(0.0, 1.0), [255, 255, 255]);
        assert_eq!(map.feature_at(1.0, 0.0), [1.0, 1.0, 1.0]);
        assert_eq!(map.feature_at(1.5, -3.0), [1.0, 1.0, 1.0], "positions outside [0, 1]² are clamped");
        assert_eq!(pixel_index(0.5), 229);
    }
}
