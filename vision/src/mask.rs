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
        let lo = floor.rgb_min;
        // An empty range (min > max) holds nothing: span 0 would still hold p == lo.
        let empty = (0..3).any(|k| floor.rgb_min[k] > floor.rgb_max[k]);
        if empty {
            self.data.iter_mut().for_each(|m| *m = 0);
            return;
        }
        // Four bytes a pixel as one 32-bit word (R in the low byte), and every byte compared
        // at once in it ("SWAR", so that the compiler vectorises the loop over 32-bit lanes):
        // per byte, `d = p - lo` (wrapping) and then `d <= hi - lo`, which holds exactly when
        // `lo <= p <= hi`. Alpha is left out.
        const H: u32 = 0x8080_8080;
        const RGB_HIGH: u32 = 0x0080_8080;
        let word = |b: [u8; 3]| u32::from_le_bytes([b[0], b[1], b[2], 0]);
        let lo = word(lo);
        let span = word([0, 1, 2].map(|k| floor.rgb_max[k] - floor.rgb_min[k]));
        let raw = img.as_raw();
        let stride = img.width() as usize * 4;
        for y in 0..h {
            let row = &raw[(y + y0) * stride + x0 * 4..(y + y0) * stride + x1 * 4];
            let (pixels, _) = row.as_chunks::<4>();
            for (o, p) in self.data[y * w..(y + 1) * w].iter_mut().zip(pixels) {
                let p = u32::from_le_bytes(*p);
                // Bytewise p - lo with no borrow between bytes.
                let d = ((p | H).wrapping_sub(lo & !H)) ^ ((p ^ !lo) & H);
                // Bytewise span >= d: the high bits decide, else the low seven.
                let low = (span | H).wrapping_sub(d & !H);
                let ge = ((span & !d) | (!(span ^ d) & low)) & RGB_HIGH;
                *o = (ge == RGB_HIGH) as u8;
            }
        }
    }

    /// The first and last set row of every column (`None` for an empty column), in one pass
    /// over the rows (branch-free, so that the compiler vectorises it).
    pub fn column_extents(&self) -> Vec<Option<(usize, usize)>> {
        let w = self.width;
        // Rows as u32: first (u32::MAX while unset) and last set row + 1 (0 while unset),
        // updated through all-ones / all-zeros lane masks.
        let mut first = vec![u32::MAX; w];
        let mut last = vec![0u32; w];
        for (v, row) in self.data.chunks_exact(w.max(1)).enumerate() {
            let v = v as u32;
            let (first, last, row) = (&mut first[..w], &mut last[..w], &row[..w]);
            for i in 0..w {
                let set = 0u32.wrapping_sub((row[i] != 0) as u32);
                first[i] = first[i].min((v & set) | !set);
                last[i] = (last[i] & !set) | ((v + 1) & set);
            }
        }
        first
            .iter()
            .zip(&last)
            .map(|(&f, &l)| (l > 0).then(|| (f as usize, l as usize - 1)))
            .collect()
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
        // Along rows, into the scratch: the three neighbours as shifted slices, so that each
        // pass is one vectorisable zip.
        for (row, out) in self.data.chunks_exact(w).zip(scratch.chunks_exact_mut(w)) {
            out.copy_from_slice(row);
            if w > 1 {
                out[0] = op(row[0], row[1]);
                out[w - 1] = op(row[w - 1], row[w - 2]);
                for (o, ((&l, &c), &r)) in out[1..w - 1]
                    .iter_mut()
                    .zip(row.iter().zip(&row[1..]).zip(&row[2..]))
                {
                    *o = op(op(l, c), r);
                }
            }
        }
        // Along columns, back into the mask.
        for y in 0..h {
            let out = &mut self.data[y * w..(y + 1) * w];
            let centre = &scratch[y * w..(y + 1) * w];
            let up = &scratch[y.saturating_sub(1) * w..(y.saturating_sub(1) + 1) * w];
            let down = &scratch[(y + 1).min(h - 1) * w..((y + 1).min(h - 1) + 1) * w];
            for (o, ((&u, &c), &d)) in out.iter_mut().zip(up.iter().zip(centre).zip(down)) {
                *o = op(op(u, c), d);
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

    #[test]
    fn binarization_agrees_with_the_colour_box_for_every_red_and_green() {
        // Every (r, g) pair, with blue at and around the box's bounds and the extremes, alpha
        // anything: the word-at-a-time comparison must give exactly the box's answer.
        let boxes = [
            FloorColor::default(),
            FloorColor {
                rgb_min: [0, 0, 0],
                rgb_max: [255, 255, 255],
            },
            FloorColor {
                rgb_min: [128, 127, 129],
                rgb_max: [128, 200, 255],
            },
            FloorColor {
                rgb_min: [1, 254, 0],
                rgb_max: [254, 255, 0],
            },
        ];
        let mut m = Mask::new(0, 0);
        for floor in &boxes {
            let (lo, hi) = (floor.rgb_min[2], floor.rgb_max[2]);
            let blues = [
                0,
                1,
                127,
                128,
                254,
                255,
                lo,
                hi,
                lo.saturating_sub(1),
                hi.saturating_add(1),
            ];
            for b in blues {
                let img = RgbaImage::from_fn(256, 256, |r, g| {
                    image::Rgba([r as u8, g as u8, b, (r ^ g) as u8])
                });
                m.binarize(&img, floor);
                for (k, p) in img.pixels().enumerate() {
                    let want = floor.contains([p[0], p[1], p[2]]);
                    assert_eq!(m.data[k] == 1, want, "{p:?} in {floor:?}");
                }
            }
        }
    }

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
