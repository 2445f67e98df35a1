//! Harris corners (Harris and Stephens 1988; Sect. 2.2.2): the response
//! `R = det(M) - k trace(M)^2` of the structure tensor `M`, the Gaussian-weighted sum of the
//! products of the image gradients, kept at local maxima above a fraction of the strongest.

use super::grey::Grey;
use imageproc::kernel::Kernel;
use serde::{Deserialize, Serialize};

/// Settings of the corner detector (`[vision.forward.odometry.harris]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HarrisConfig {
    /// `k` of the response.
    pub k: f32,
    /// Width of the Gaussian window of the structure tensor, px.
    pub sigma_px: f32,
    /// Corners must respond at least this fraction of the strongest one.
    pub relative_threshold: f32,
    /// And at least this (absolute floor, so a flat noisy image has none).
    pub min_response: f32,
    /// Smallest distance between two corners kept, px.
    pub min_distance_px: f64,
    /// Most corners kept (the strongest).
    pub max_corners: usize,
}

impl Default for HarrisConfig {
    fn default() -> Self {
        Self {
            k: 0.05,
            sigma_px: 1.2,
            relative_threshold: 0.02,
            min_response: 2.0e5,
            min_distance_px: 6.0,
            max_corners: 60,
        }
    }
}

/// A corner: pixel position and response.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corner {
    /// Column.
    pub x: u32,
    /// Row.
    pub y: u32,
    /// Harris response.
    pub response: f32,
}

/// The Harris response of every pixel.
pub fn harris_response(img: &Grey, k: f32, sigma_px: f32) -> Grey {
    const SX: [f32; 9] = [-1.0, 0.0, 1.0, -2.0, 0.0, 2.0, -1.0, 0.0, 1.0];
    const SY: [f32; 9] = [-1.0, -2.0, -1.0, 0.0, 0.0, 0.0, 1.0, 2.0, 1.0];
    let gx: Grey = imageproc::filter::filter(img, Kernel::new(&SX, 3, 3), |p| p);
    let gy: Grey = imageproc::filter::filter(img, Kernel::new(&SY, 3, 3), |p| p);
    let (w, h) = img.dimensions();
    let product = |f: &dyn Fn(f32, f32) -> f32| {
        Grey::from_fn(w, h, |x, y| {
            image::Luma([f(gx.get_pixel(x, y).0[0], gy.get_pixel(x, y).0[0])])
        })
    };
    let blur = |g: Grey| imageproc::filter::gaussian_blur_f32(&g, sigma_px);
    let xx = blur(product(&|a, _| a * a));
    let yy = blur(product(&|_, b| b * b));
    let xy = blur(product(&|a, b| a * b));
    Grey::from_fn(w, h, |x, y| {
        let (a, b, c) = (
            xx.get_pixel(x, y).0[0],
            yy.get_pixel(x, y).0[0],
            xy.get_pixel(x, y).0[0],
        );
        image::Luma([a * b - c * c - k * (a + b) * (a + b)])
    })
}

/// The corners of `img` inside rows `rows` (and `border` px from the sides), strongest first.
pub fn harris_corners(
    img: &Grey,
    config: &HarrisConfig,
    rows: std::ops::Range<u32>,
    border: u32,
) -> Vec<Corner> {
    let r = harris_response(img, config.k, config.sigma_px);
    let (w, h) = r.dimensions();
    let y0 = rows.start.max(border).max(1);
    let y1 = rows.end.min(h.saturating_sub(border)).min(h - 1);
    let x0 = border.max(1);
    let x1 = w.saturating_sub(border).min(w - 1);
    let mut strongest = 0.0f32;
    let mut candidates = Vec::new();
    for y in y0..y1 {
        for x in x0..x1 {
            let v = r.get_pixel(x, y).0[0];
            let is_max = (-1i32..=1).all(|dy| {
                (-1i32..=1).all(|dx| {
                    (dx == 0 && dy == 0)
                        || r.get_pixel((x as i32 + dx) as u32, (y as i32 + dy) as u32)
                            .0[0]
                            < v
                })
            });
            if is_max && v > config.min_response {
                strongest = strongest.max(v);
                candidates.push(Corner { x, y, response: v });
            }
        }
    }
    candidates.retain(|c| c.response >= config.relative_threshold * strongest);
    candidates.sort_by(|a, b| {
        b.response
            .total_cmp(&a.response)
            .then((a.y, a.x).cmp(&(b.y, b.x)))
    });
    let d2 = config.min_distance_px * config.min_distance_px;
    let mut kept: Vec<Corner> = Vec::new();
    for c in candidates {
        if kept.len() >= config.max_corners {
            break;
        }
        let far = kept.iter().all(|k| {
            let (dx, dy) = (k.x as f64 - c.x as f64, k.y as f64 - c.y as f64);
            dx * dx + dy * dy >= d2
        });
        if far {
            kept.push(c);
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Luma;

    #[test]
    fn corners_respond_and_edges_do_not() {
        // A dark square (corners at 30/60) and a long vertical edge at x = 100.
        let img = Grey::from_fn(128, 96, |x, y| {
            let square = (30..60).contains(&x) && (30..60).contains(&y);
            let right = x >= 100;
            Luma([if square || right { 40.0 } else { 200.0 }])
        });
        let r = harris_response(&img, 0.05, 1.2);
        let at = |x: u32, y: u32| r.get_pixel(x, y).0[0];
        // A corner responds strongly; the middle of an edge is negative (one large eigenvalue);
        // flat ground is zero.
        assert!(at(30, 30) > 1e6, "{}", at(30, 30));
        assert!(at(45, 30) < 0.0 && at(100, 50) < 0.0);
        assert_eq!(at(80, 80), 0.0);
        let corners = harris_corners(&img, &HarrisConfig::default(), 0..96, 4);
        assert_eq!(corners.len(), 4, "{corners:?}");
        for c in &corners {
            let near = |v: u32, a: u32| v.abs_diff(a) <= 1;
            assert!(
                (near(c.x, 30) || near(c.x, 59)) && (near(c.y, 30) || near(c.y, 59)),
                "{c:?}"
            );
        }
    }
}
