//! Lucas-Kanade feature tracking (Lucas and Kanade 1981; Sect. 2.2.2, eq. (6)): the
//! displacement `d` of a feature minimising the residual
//! `e(d) = sum over the window (I1(x, y) - I2(x + d_x, y + d_y))^2`, by Gauss-Newton steps
//! `d += G^-1 b` with `G` the window's gradient matrix. The paper tracks on one level; we run it
//! coarse to fine over a pyramid of images halved in size (ours), so that the several pixels a
//! feature moves near the bottom of the image between two frames stay within reach.

use super::flow::reduce;
use super::grey::{Grey, bilinear};
use serde::{Deserialize, Serialize};

/// Settings of the tracker (`[vision.forward.odometry.lk]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LkConfig {
    /// Half the window `w_x = w_y` of eq. (6), px.
    pub half_window_px: u32,
    /// Pyramid levels (1: the paper's single level).
    pub levels: u32,
    /// Most Gauss-Newton steps a level.
    pub iterations: u32,
    /// A step shorter than this ends a level, px.
    pub epsilon_px: f64,
    /// A track whose mean absolute residual over the window exceeds this is lost, grey levels.
    pub max_residual: f32,
    /// Gaussian smoothing of the images before tracking, px (sharp edges lock a track to whole
    /// pixels).
    pub smooth_sigma_px: f32,
}

impl Default for LkConfig {
    fn default() -> Self {
        Self {
            half_window_px: 5,
            levels: 3,
            iterations: 20,
            epsilon_px: 0.01,
            max_residual: 18.0,
            smooth_sigma_px: 1.0,
        }
    }
}

/// An image pyramid: the image smoothed by `sigma_px` (none at 0), then halved (block means)
/// `levels - 1` times.
pub fn pyramid(img: &Grey, levels: u32, sigma_px: f32) -> Vec<Grey> {
    let base = if sigma_px > 0.0 {
        imageproc::filter::gaussian_blur_f32(img, sigma_px)
    } else {
        img.clone()
    };
    let mut out = Vec::with_capacity(levels.max(1) as usize);
    let mut level = base;
    for _ in 1..levels.max(1) {
        let next = reduce(&level, 2);
        out.push(std::mem::replace(&mut level, next));
    }
    out.push(level);
    out
}

/// Where the features at `points` of image `a` are in image `b`, starting from `guesses`
/// (the same length); `None` for a track that was lost (left the image, a flat window, or a
/// residual too large).
pub fn track_lk(
    a: &[Grey],
    b: &[Grey],
    points: &[(f64, f64)],
    guesses: &[(f64, f64)],
    config: &LkConfig,
) -> Vec<Option<(f64, f64)>> {
    points
        .iter()
        .zip(guesses)
        .map(|(&p, &g)| track_one(a, b, p, g, config))
        .collect()
}

/// Full-resolution pixel coordinates at pyramid level `l` (block means keep pixel edges).
fn to_level(v: f64, l: usize) -> f64 {
    (v + 0.5) / (1u32 << l) as f64 - 0.5
}

fn track_one(
    a: &[Grey],
    b: &[Grey],
    p: (f64, f64),
    guess: (f64, f64),
    config: &LkConfig,
) -> Option<(f64, f64)> {
    let levels = a.len().min(b.len());
    let hw = config.half_window_px as i32;
    let top = levels - 1;
    let mut g = (
        to_level(guess.0, top) - to_level(p.0, top),
        to_level(guess.1, top) - to_level(p.1, top),
    );
    for l in (0..levels).rev() {
        let (ia, ib) = (&a[l], &b[l]);
        let (px, py) = (to_level(p.0, l), to_level(p.1, l));
        let mut window = Vec::with_capacity(((2 * hw + 1) * (2 * hw + 1)) as usize);
        let (mut gxx, mut gxy, mut gyy) = (0.0f64, 0.0f64, 0.0f64);
        for dy in -hw..=hw {
            for dx in -hw..=hw {
                let (x, y) = (px + dx as f64, py + dy as f64);
                let ix = 0.5 * (bilinear(ia, x + 1.0, y) - bilinear(ia, x - 1.0, y)) as f64;
                let iy = 0.5 * (bilinear(ia, x, y + 1.0) - bilinear(ia, x, y - 1.0)) as f64;
                gxx += ix * ix;
                gxy += ix * iy;
                gyy += iy * iy;
                window.push((x, y, bilinear(ia, x, y), ix, iy));
            }
        }
        let det = gxx * gyy - gxy * gxy;
        let trace = gxx + gyy;
        // A flat or one-directional window cannot be tracked (aperture problem).
        if det <= 1e-3 * trace * trace || trace < 1e-6 {
            return None;
        }
        for _ in 0..config.iterations {
            let (mut bx, mut by) = (0.0f64, 0.0f64);
            for &(x, y, va, ix, iy) in &window {
                let e = (va - bilinear(ib, x + g.0, y + g.1)) as f64;
                bx += e * ix;
                by += e * iy;
            }
            let step = ((gyy * bx - gxy * by) / det, (gxx * by - gxy * bx) / det);
            g = (g.0 + step.0, g.1 + step.1);
            if step.0.hypot(step.1) < config.epsilon_px {
                break;
            }
        }
        if l > 0 {
            g = (2.0 * g.0, 2.0 * g.1);
        }
    }
    let q = (p.0 + g.0, p.1 + g.1);
    let (w, h) = (a[0].width() as f64, a[0].height() as f64);
    let m = hw as f64;
    if !(q.0 >= m && q.1 >= m && q.0 <= w - 1.0 - m && q.1 <= h - 1.0 - m) {
        return None;
    }
    let mut residual = 0.0f32;
    let mut n = 0.0f32;
    for dy in -hw..=hw {
        for dx in -hw..=hw {
            let (dx, dy) = (dx as f64, dy as f64);
            residual +=
                (bilinear(&a[0], p.0 + dx, p.1 + dy) - bilinear(&b[0], q.0 + dx, q.1 + dy)).abs();
            n += 1.0;
        }
    }
    (residual / n <= config.max_residual).then_some(q)
}

#[cfg(test)]
mod tests {
    use super::super::testing::squares;
    use super::*;

    fn tracked(dx: f64, dy: f64) -> Vec<(f64, f64)> {
        let a = pyramid(&squares(128, 96, 0.0, 0.0), 3, 1.0);
        let b = pyramid(&squares(128, 96, dx, dy), 3, 1.0);
        // The squares' corners.
        let pts = [(48.0, 28.0), (72.0, 52.0), (30.0, 60.0), (50.0, 80.0)];
        let out = track_lk(&a, &b, &pts, &pts, &LkConfig::default());
        pts.iter()
            .zip(out)
            .map(|(p, q)| {
                let Some(q) = q else {
                    panic!("({dx},{dy}) {p:?} lost")
                };
                (q.0 - p.0, q.1 - p.1)
            })
            .collect()
    }

    #[test]
    fn integer_and_sub_pixel_shifts_are_recovered() {
        for (dx, dy) in [(3.0, -2.0), (0.4, 0.25), (-1.7, 0.0), (6.0, 4.0)] {
            for (u, v) in tracked(dx, dy) {
                assert!(
                    (u - dx).abs() < 0.1 && (v - dy).abs() < 0.1,
                    "({dx},{dy}) -> ({u},{v})"
                );
            }
        }
    }

    #[test]
    fn a_flat_window_is_not_tracked() {
        let a = pyramid(&squares(128, 96, 0.0, 0.0), 2, 1.0);
        let out = track_lk(
            &a,
            &a,
            &[(80.0, 60.0)],
            &[(80.0, 60.0)],
            &LkConfig::default(),
        );
        assert_eq!(out, vec![None]);
    }
}
