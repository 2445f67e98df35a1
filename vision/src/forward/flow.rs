//! Optical flow by Horn and Schunck, and the balance of its magnitudes between the left and
//! the right of the image (Sect. 2.1.2, eqs. (1)-(2)).
//!
//! The derivatives `E_x`, `E_y`, `E_t` are Horn and Schunck's own: first differences averaged
//! over the 2x2x2 cube of two frames; the local averages `u_bar`, `v_bar` use their 3x3 kernel
//! (1/6 at the sides, 1/12 at the corners). Each iteration applies eqs. (1)-(2) everywhere.

use super::grey::Grey;
use serde::{Deserialize, Serialize};

/// Settings of the flow and of the flow-balance avoidance (`[vision.forward.flow]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FlowConfig {
    /// The weighting factor `alpha` of eqs. (1)-(2), grey levels per pixel.
    pub alpha: f32,
    /// Iterations of eqs. (1)-(2).
    pub iterations: u32,
    /// The images are reduced by this factor (averaging blocks) before the flow (1: not).
    pub downsample: u32,
    /// Rows from the top of the image left out (far away: little flow, the horizon's clutter),
    /// as a fraction of the height.
    pub skip_top: f64,
    /// Mean flow magnitude over the half with more flow (px a frame, full resolution) past
    /// which an obstacle is taken to be near (ours: the paper compares "the flow" with a
    /// threshold; an obstacle on a plain floor fills one side first and its flow, only along its
    /// edges, is diluted by the other half's floor in a mean over both).
    pub threshold_px: f32,
}

impl Default for FlowConfig {
    fn default() -> Self {
        Self {
            alpha: 15.0,
            iterations: 60,
            downsample: 2,
            skip_top: 0.25,
            threshold_px: 0.45,
        }
    }
}

/// A flow field: `u` (right) and `v` (down) in pixels a frame, row by row.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowField {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Horizontal flow.
    pub u: Vec<f32>,
    /// Vertical flow.
    pub v: Vec<f32>,
}

impl FlowField {
    /// The mean of `u` and of `v` over the field.
    pub fn mean(&self) -> (f32, f32) {
        let n = self.u.len().max(1) as f32;
        (
            self.u.iter().sum::<f32>() / n,
            self.v.iter().sum::<f32>() / n,
        )
    }
}

/// The mean flow magnitude over the left and the right half of the image (below `skip_top`),
/// in pixels a frame at full resolution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlowBalance {
    /// Left half.
    pub left_px: f32,
    /// Right half.
    pub right_px: f32,
}

impl FlowBalance {
    /// The balance of `field` (computed on images reduced by `scale`).
    pub fn of(field: &FlowField, skip_top: f64, scale: u32) -> Self {
        let (w, h) = (field.width as usize, field.height as usize);
        let top = ((skip_top * h as f64).round() as usize).min(h.saturating_sub(1));
        let half = w / 2;
        let (mut l, mut r) = (0.0f32, 0.0f32);
        for y in top..h {
            for x in 0..w {
                let i = y * w + x;
                let m = field.u[i].hypot(field.v[i]);
                if x < half {
                    l += m;
                } else {
                    r += m;
                }
            }
        }
        let rows = (h - top).max(1) as f32;
        let s = scale as f32;
        Self {
            left_px: s * l / (rows * half.max(1) as f32),
            right_px: s * r / (rows * (w - half).max(1) as f32),
        }
    }

    /// The mean over both halves.
    pub fn total_px(&self) -> f32 {
        0.5 * (self.left_px + self.right_px)
    }

    /// The mean over the half with more flow.
    pub fn larger_px(&self) -> f32 {
        self.left_px.max(self.right_px)
    }
}

/// `img` reduced by `k`: each output pixel the mean of a `k x k` block.
pub fn reduce(img: &Grey, k: u32) -> Grey {
    if k <= 1 {
        return img.clone();
    }
    let (w, h) = (img.width() / k, img.height() / k);
    Grey::from_fn(w.max(1), h.max(1), |x, y| {
        let mut s = 0.0;
        for dy in 0..k {
            for dx in 0..k {
                s += img
                    .get_pixel(
                        (x * k + dx).min(img.width() - 1),
                        (y * k + dy).min(img.height() - 1),
                    )
                    .0[0];
            }
        }
        image::Luma([s / (k * k) as f32])
    })
}

/// Horn-Schunck flow from `a` to `b` (equal sizes) by `iterations` of eqs. (1)-(2) from zero.
pub fn horn_schunck(a: &Grey, b: &Grey, alpha: f32, iterations: u32) -> FlowField {
    let (w, h) = a.dimensions();
    let (wu, hu) = (w as usize, h as usize);
    let at = |img: &Grey, x: usize, y: usize| {
        img.get_pixel(x.min(wu - 1) as u32, y.min(hu - 1) as u32).0[0]
    };
    let n = wu * hu;
    let (mut ex, mut ey, mut et) = (vec![0.0f32; n], vec![0.0f32; n], vec![0.0f32; n]);
    for y in 0..hu {
        for x in 0..wu {
            let c = [
                at(a, x, y),
                at(a, x + 1, y),
                at(a, x, y + 1),
                at(a, x + 1, y + 1),
                at(b, x, y),
                at(b, x + 1, y),
                at(b, x, y + 1),
                at(b, x + 1, y + 1),
            ];
            let i = y * wu + x;
            ex[i] = 0.25 * ((c[1] - c[0]) + (c[3] - c[2]) + (c[5] - c[4]) + (c[7] - c[6]));
            ey[i] = 0.25 * ((c[2] - c[0]) + (c[3] - c[1]) + (c[6] - c[4]) + (c[7] - c[5]));
            et[i] = 0.25 * ((c[4] - c[0]) + (c[5] - c[1]) + (c[6] - c[2]) + (c[7] - c[3]));
        }
    }
    let a2 = alpha * alpha;
    let (mut u, mut v) = (vec![0.0f32; n], vec![0.0f32; n]);
    let (mut ub, mut vb) = (vec![0.0f32; n], vec![0.0f32; n]);
    for _ in 0..iterations {
        local_average(&u, wu, &mut ub);
        local_average(&v, wu, &mut vb);
        for i in 0..n {
            let (uu, vv) = (ub[i], vb[i]);
            // Eqs. (1)-(2).
            let r = (ex[i] * uu + ey[i] * vv + et[i]) / (a2 + ex[i] * ex[i] + ey[i] * ey[i]);
            u[i] = uu - ex[i] * r;
            v[i] = vv - ey[i] * r;
        }
    }
    FlowField {
        width: w,
        height: h,
        u,
        v,
    }
}

/// Horn and Schunck's 3x3 kernel of the local averages: 1/6 at the sides, 1/12 at the corners,
/// row by row.
const AVERAGE: [f32; 9] = [
    1.0 / 12.0,
    1.0 / 6.0,
    1.0 / 12.0,
    1.0 / 6.0,
    0.0,
    1.0 / 6.0,
    1.0 / 12.0,
    1.0 / 6.0,
    1.0 / 12.0,
];

/// `u_bar` of eqs. (1)-(2): `field` (rows of `width` values) correlated with [`AVERAGE`] into
/// `out`, the borders padded by continuity. The sum runs over the kernel row by row from zero,
/// the centre's zero weight included, as `imageproc::filter::filter` sums it: the same values
/// to the last bit, without its per-tap clamping.
fn local_average(field: &[f32], width: usize, out: &mut [f32]) {
    let height = field.len().checked_div(width).unwrap_or(0);
    let k = AVERAGE;
    for y in 0..height {
        let rows =
            [y.saturating_sub(1), y, (y + 1).min(height - 1)].map(|r| &field[r * width..][..width]);
        let out = &mut out[y * width..][..width];
        let at_edge = |x: usize| {
            let cols = [x.saturating_sub(1), x, (x + 1).min(width - 1)];
            let mut acc = 0.0f32;
            for (row, k) in rows.iter().zip(k.chunks_exact(3)) {
                for (&c, &kk) in cols.iter().zip(k) {
                    acc += row[c] * kk;
                }
            }
            acc
        };
        // Inside the row the same sum, term by term in the same order, on three windows (the
        // compiler vectorises it across the row); the first and last column pad.
        let [r0, r1, r2] = rows;
        let inner = r0.windows(3).zip(r1.windows(3)).zip(r2.windows(3));
        for (o, ((a, b), c)) in out.iter_mut().skip(1).zip(inner) {
            let mut acc = 0.0f32;
            acc += a[0] * k[0];
            acc += a[1] * k[1];
            acc += a[2] * k[2];
            acc += b[0] * k[3];
            acc += b[1] * k[4];
            acc += b[2] * k[5];
            acc += c[0] * k[6];
            acc += c[1] * k[7];
            acc += c[2] * k[8];
            *o = acc;
        }
        for x in [0, width.saturating_sub(1)] {
            if x < width {
                out[x] = at_edge(x);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing::texture;
    use super::*;

    #[test]
    fn the_local_average_is_imageprocs_correlation_to_the_bit() {
        // Odd sizes, one-pixel-wide strips, empty images, signed values and zeros of both signs.
        for (w, h) in [(7usize, 5usize), (1, 4), (6, 1), (1, 1), (0, 3), (4, 0)] {
            let field: Vec<f32> = (0..w * h)
                .map(|i| match i % 5 {
                    0 => -0.0,
                    1 => 0.0,
                    k => ((i * 37 % 101) as f32 - 50.0) / (k as f32 * 7.0),
                })
                .collect();
            let img = Grey::from_raw(w as u32, h as u32, field.clone()).unwrap();
            let kernel = imageproc::kernel::Kernel::new(&AVERAGE, 3, 3);
            let theirs: Grey = imageproc::filter::filter(&img, kernel, |p| p);
            let mut ours = vec![f32::NAN; w * h];
            local_average(&field, w, &mut ours);
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&ours), bits(theirs.as_raw()), "{w}x{h}");
        }
        let empty = Grey::new(0, 3);
        assert!(horn_schunck(&empty, &empty, 10.0, 5).u.is_empty());
    }

    #[test]
    fn a_known_translation_of_a_texture_is_recovered() {
        for (dx, dy) in [(0.5f64, 0.0f64), (0.0, -0.4), (0.6, 0.3)] {
            let a = texture(96, 72, 0.0, 0.0);
            let b = texture(96, 72, dx, dy);
            let f = horn_schunck(&a, &b, 10.0, 200);
            // Away from the borders, where the one-sided differences bias the flow.
            let (mut su, mut sv, mut k) = (0.0, 0.0, 0.0);
            for y in 8..64 {
                for x in 8..88 {
                    su += f.u[y * 96 + x] as f64;
                    sv += f.v[y * 96 + x] as f64;
                    k += 1.0;
                }
            }
            let (u, v) = (su / k, sv / k);
            assert!(
                (u - dx).abs() < 0.08 && (v - dy).abs() < 0.08,
                "({dx},{dy}) -> ({u},{v})"
            );
        }
    }

    #[test]
    fn the_balance_leans_to_the_side_that_moves() {
        let field = FlowField {
            width: 4,
            height: 2,
            u: vec![0.0, 0.0, 1.0, 3.0, 0.0, 0.0, 1.0, 3.0],
            v: vec![0.0; 8],
        };
        let b = FlowBalance::of(&field, 0.0, 2);
        assert_eq!(b.left_px, 0.0);
        assert_eq!(b.right_px, 4.0);
        assert_eq!(b.total_px(), 2.0);
        assert_eq!(b.larger_px(), 4.0);
    }
}
