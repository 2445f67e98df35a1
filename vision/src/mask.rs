//! Binary masks: floor-colour binarization and 3x3 erosion / dilation (Step 1 of Sects. 3.1
//! and 4 of the corner paper).

use image::RgbaImage;
use serde::{Deserialize, Serialize};

/// Floor colour as a box in RGB: a pixel is floor when every channel lies within its bounds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FloorColor {
    /// Lower bound per channel.
    pub rgb_min: [u8; 3],
    /// Upper bound per channel.
    pub rgb_max: [u8; 3],
}

impl Default for FloorColor {
    /// The field green of omniloop's worlds ([30, 130, 55]) with room for noise and shading.
    fn default() -> Self {
        Self {
            rgb_min: [0, 95, 20],
            rgb_max: [75, 175, 95],
        }
    }
}

impl FloorColor {
    /// Whether a pixel is floor-coloured.
    pub fn contains(&self, p: [u8; 3]) -> bool {
        (0..3).all(|k| p[k] >= self.rgb_min[k] && p[k] <= self.rgb_max[k])
    }
}

/// A binary image, one byte a pixel (0 or 1), row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct Mask {
    /// Width.
    pub width: usize,
    /// Height.
    pub height: usize,
    /// Pixels, 0 or 1.
    pub data: Vec<u8>,
}

impl Mask {
    /// An all-zero mask.
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            data: vec![0; width * height],
        }
    }

    /// Sets `self` to the floor-colour classification of `img`.
    pub fn binarize(&mut self, img: &RgbaImage, floor: &FloorColor) {
        self.binarize_region(
            img,
            floor,
            [0, 0, img.width() as usize, img.height() as usize],
        );
    }

    /// Sets `self` to the floor-colour classification of the region `[x0, y0, x1, y1)` of
    /// `img` (the mask's pixel (0, 0) is the image's (x0, y0)).
    pub fn binarize_region(&mut self, img: &RgbaImage, floor: &FloorColor, region: [usize; 4]) {
        let [x0, y0, x1, y1] = region;
        let (w, h) = (x1 - x0, y1 - y0);
        self.width = w;
        self.height = h;
        self.data.resize(w * h, 0);
        let (lo, hi) = (floor.rgb_min, floor.rgb_max);
        let raw = img.as_raw();
        let stride = img.width() as usize * 4;
        for y in 0..h {
            let row = &raw[(y + y0) * stride + x0 * 4..(y + y0) * stride + x1 * 4];
            for (o, p) in self.data[y * w..(y + 1) * w]
                .iter_mut()
                .zip(row.chunks_exact(4))
            {
                *o = (p[0] >= lo[0]
                    && p[0] <= hi[0]
                    && p[1] >= lo[1]
                    && p[1] <= hi[1]
                    && p[2] >= lo[2]
                    && p[2] <= hi[2]) as u8;
            }
        }
    }

    /// The first and last set row of every column (`None` for an empty column), in one pass
    /// over the rows.
    pub fn column_extents(&self) -> Vec<Option<(usize, usize)>> {
        let mut ext: Vec<Option<(usize, usize)>> = vec![None; self.width];
        for (v, row) in self.data.chunks_exact(self.width.max(1)).enumerate() {
            for (e, &m) in ext.iter_mut().zip(row) {
                if m != 0 {
                    *e = Some(e.map_or((v, v), |(a, _)| (a, v)));
                }
            }
        }
        ext
    }

    /// Value at `(x, y)`.
    pub fn get(&self, x: usize, y: usize) -> u8 {
        self.data[y * self.width + x]
    }

    /// 3x3 erosion (min) or dilation (max), separably, with `scratch` as the intermediate.
    /// Pixels beyond the border count as the operation's neutral value. Written as whole-row
    /// slice operations so that the compiler vectorises them.
    fn filter3(&mut self, scratch: &mut Vec<u8>, dilate: bool) {
        if dilate {
            self.filter3_with(scratch, |a, b| a | b);
        } else {
            self.filter3_with(scratch, |a, b| a & b);
        }
    }

    fn filter3_with(&mut self, scratch: &mut Vec<u8>, op: impl Fn(u8, u8) -> u8 + Copy) {
        let (w, h) = (self.width, self.height);
        scratch.resize(w * h, 0);
        if w == 0 || h == 0 {
            return;
        }
        // Along rows.
        for (row, out) in self.data.chunks_exact(w).zip(scratch.chunks_exact_mut(w)) {
            out.copy_from_slice(row);
            if w > 1 {
                for (o, &r) in out[..w - 1].iter_mut().zip(&row[1..]) {
                    *o = op(*o, r);
                }
                for (o, &l) in out[1..].iter_mut().zip(&row[..w - 1]) {
                    *o = op(*o, l);
                }
            }
        }
        // Along columns.
        self.data.copy_from_slice(scratch);
        for y in 0..h {
            let out = &mut self.data[y * w..(y + 1) * w];
            if y > 0 {
                for (o, &u) in out.iter_mut().zip(&scratch[(y - 1) * w..y * w]) {
                    *o = op(*o, u);
                }
            }
            if y + 1 < h {
                for (o, &d) in out.iter_mut().zip(&scratch[(y + 1) * w..(y + 2) * w]) {
                    *o = op(*o, d);
                }
            }
        }
    }

    /// 3x3 erosion.
    pub fn erode(&mut self, scratch: &mut Vec<u8>) {
        self.filter3(scratch, false);
    }

    /// 3x3 dilation.
    pub fn dilate(&mut self, scratch: &mut Vec<u8>) {
        self.filter3(scratch, true);
    }

    /// Removes noise: closing (dilate then erode, `n` times each) fills small non-floor specks
    /// such as thin lines, then opening (erode then dilate) removes small floor specks.
    pub fn clean(&mut self, n: u32, scratch: &mut Vec<u8>) {
        for _ in 0..n {
            self.dilate(scratch);
        }
        for _ in 0..n {
            self.erode(scratch);
        }
        for _ in 0..n {
            self.erode(scratch);
        }
        for _ in 0..n {
            self.dilate(scratch);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mask(rows: &[&str]) -> Mask {
        let h = rows.len();
        let w = rows[0].len();
        let data = rows
            .iter()
            .flat_map(|r| r.bytes().map(|b| (b == b'#') as u8))
            .collect();
        Mask {
            width: w,
            height: h,
            data,
        }
    }

    #[test]
    fn cleaning_removes_specks_and_thin_lines_but_keeps_blocks() {
        let mut m = mask(&[
            "##########",
            "##########",
            "####.#####",
            "##########",
            "..........",
            "..........",
            "...#......",
            "..........",
            "..........",
            "..........",
        ]);
        let mut s = Vec::new();
        m.clean(1, &mut s);
        // The hole at (4, 2) is filled, the speck at (3, 6) is gone, the block stays.
        assert_eq!(m.get(4, 2), 1);
        assert_eq!(m.get(3, 6), 0);
        assert_eq!(m.get(0, 0), 1);
        assert_eq!(m.get(5, 8), 0);
    }

    #[test]
    fn binarization_uses_the_colour_box() {
        let mut img = RgbaImage::new(2, 1);
        img.put_pixel(0, 0, image::Rgba([30, 130, 55, 255]));
        img.put_pixel(1, 0, image::Rgba([235, 235, 235, 255]));
        let mut m = Mask::new(0, 0);
        m.binarize(&img, &FloorColor::default());
        assert_eq!(m.data, vec![1, 0]);
    }
}
