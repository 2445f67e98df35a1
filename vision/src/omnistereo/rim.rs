//! The mirror's rim in the image: its centre (the image of the mirror axis) and its radius
//! `r_m`, from which eq. (2) calibrates the camera, `v = (d / R + 1) r_m` (Sect. 2).
//!
//! Outside the rim the camera sees nothing of the mirror (black, up to the sensor's noise). The
//! boundary is found between every pair of 4-neighbour pixels of which one is lit and the other
//! dark, at their midpoint, and a circle is fitted to those points by linear least squares
//! (Kasa's algebraic fit, `x^2 + y^2 + D x + E y + F = 0`); then fits again on the points within
//! `max(2, 3 m)` px of the last fit (`m` the median distance of all points from it), until the
//! points kept stay the same (at most five fits): dark scene pixels inside the rim, and the few
//! black pixels that noise lifts above the threshold, drop out however far they are. A bright
//! pixel with fewer than two bright 4-neighbours is noise in the black, not the mirror, and
//! counts as dark. With
//! pixels sampled at their centres the midpoint is an unbiased place for the edge, and a few
//! thousand of them put the radius within a tenth of a pixel.

use crate::VisionError;
use image::RgbaImage;
use nalgebra::{Matrix3, Vector3};

/// A pixel is bright when its brightest channel exceeds this: six sigma of the sensor noise (4
/// grey levels) above black.
const LIT: u8 = 24;

/// The image of the mirror's rim.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MirrorRim {
    /// Centre, pixel coordinates (x right, y down; pixel `(u, v)` covers `[u, u + 1)`).
    pub centre_px: [f64; 2],
    /// Radius `r_m`, px.
    pub radius_px: f64,
    /// Boundary points the fit used.
    pub points: usize,
}

impl MirrorRim {
    /// Measures the rim of the (single) mirror disc in `img`.
    pub fn measure(img: &RgbaImage) -> Result<Self, VisionError> {
        let points = boundary_points(img);
        let mut rim = fit_circle(&points)?;
        let mut kept_before = points.len() + 1;
        for _ in 0..4 {
            let mut off: Vec<f64> = points
                .iter()
                .map(|p| (rim.distance(p) - rim.radius_px).abs())
                .collect();
            let tol = {
                let mut sorted = off.clone();
                sorted.sort_by(f64::total_cmp);
                (3.0 * sorted[sorted.len() / 2]).max(2.0)
            };
            let kept: Vec<[f64; 2]> = points
                .iter()
                .zip(off.iter_mut())
                .filter(|(_, d)| **d <= tol)
                .map(|(p, _)| *p)
                .collect();
            if kept.len() == kept_before {
                break;
            }
            kept_before = kept.len();
            rim = fit_circle(&kept)?;
        }
        if rim.radius_px < 8.0 {
            return Err(VisionError::NotFound(format!(
                "the lit disc is {:.1} px across: no mirror rim in the image",
                2.0 * rim.radius_px
            )));
        }
        Ok(rim)
    }

    /// Image coordinates `(X, Y)` (from the centre, Y up) of pixel `(u, v)`'s centre.
    pub fn image_coords(&self, u: f64, v: f64) -> (f64, f64) {
        (u + 0.5 - self.centre_px[0], self.centre_px[1] - (v + 0.5))
    }

    fn distance(&self, p: &[f64; 2]) -> f64 {
        (p[0] - self.centre_px[0]).hypot(p[1] - self.centre_px[1])
    }
}

/// Midpoints (pixel coordinates) of every lit / dark pair of 4-neighbours: lit is bright with
/// at least two bright 4-neighbours (inside the rim, and on its edge, every bright pixel has
/// them; in the black, noise lifts single pixels and seldom three together).
fn boundary_points(img: &RgbaImage) -> Vec<[f64; 2]> {
    let (w, h) = img.dimensions();
    let bright: Vec<bool> = img
        .pixels()
        .map(|p| p.0[0].max(p.0[1]).max(p.0[2]) > LIT)
        .collect();
    let at = |x: u32, y: u32| bright[(y * w + x) as usize];
    let lit: Vec<bool> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let neighbours = [
                x > 0 && at(x - 1, y),
                x + 1 < w && at(x + 1, y),
                y > 0 && at(x, y - 1),
                y + 1 < h && at(x, y + 1),
            ];
            at(x, y) && neighbours.iter().filter(|b| **b).count() >= 2
        })
        .collect();
    let lit_at = |x: u32, y: u32| lit[(y * w + x) as usize];
    let mut pts = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let here = lit_at(x, y);
            if x + 1 < w && lit_at(x + 1, y) != here {
                pts.push([x as f64 + 1.0, y as f64 + 0.5]);
            }
            if y + 1 < h && lit_at(x, y + 1) != here {
                pts.push([x as f64 + 0.5, y as f64 + 1.0]);
            }
        }
    }
    pts
}

/// Kasa's least-squares circle through `pts`.
fn fit_circle(pts: &[[f64; 2]]) -> Result<MirrorRim, VisionError> {
    if pts.len() < 16 {
        return Err(VisionError::NotFound(format!(
            "{} boundary points between lit and dark pixels: no mirror rim in the image",
            pts.len()
        )));
    }
    // Centre the data for conditioning.
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p[0]).sum::<f64>() / n,
        pts.iter().map(|p| p[1]).sum::<f64>() / n,
    );
    let mut ata = Matrix3::zeros();
    let mut atb = Vector3::zeros();
    for p in pts {
        let (x, y) = (p[0] - mx, p[1] - my);
        let row = Vector3::new(x, y, 1.0);
        ata += row * row.transpose();
        atb += row * -(x * x + y * y);
    }
    let sol = ata.lu().solve(&atb).ok_or_else(|| {
        VisionError::NotFound("the boundary points do not determine a circle".into())
    })?;
    let (cx, cy) = (-sol[0] / 2.0, -sol[1] / 2.0);
    let r2 = cx * cx + cy * cy - sol[2];
    if r2.is_nan() || r2 <= 0.0 {
        return Err(VisionError::NotFound(
            "the boundary points do not lie on a circle".into(),
        ));
    }
    Ok(MirrorRim {
        centre_px: [cx + mx, cy + my],
        radius_px: r2.sqrt(),
        points: pts.len(),
    })
}

/// A 512 x 512 test image: a mirror disc of radius 200 about the centre, black outside,
/// inside painted by `paint(radius_px, azimuth_rad)` (image coordinates, Y up).
#[cfg(test)]
pub(crate) fn synthetic_disc(
    paint: impl Fn(f64, f64) -> image::Rgba<u8>,
) -> (RgbaImage, MirrorRim) {
    let rim = MirrorRim {
        centre_px: [256.0, 256.0],
        radius_px: 200.0,
        points: 0,
    };
    let img = RgbaImage::from_fn(512, 512, |u, v| {
        let (x, y) = rim.image_coords(u as f64, v as f64);
        let h = x.hypot(y);
        if h >= 200.0 {
            image::Rgba([0, 0, 0, 255])
        } else {
            paint(h, y.atan2(x))
        }
    });
    (img, rim)
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgba;

    fn disc(w: u32, c: [f64; 2], r: f64) -> RgbaImage {
        RgbaImage::from_fn(w, w, |u, v| {
            let (x, y) = (u as f64 + 0.5 - c[0], v as f64 + 0.5 - c[1]);
            if x.hypot(y) < r {
                Rgba([120, 140, 90, 255])
            } else {
                Rgba([3, 0, 5, 255])
            }
        })
    }

    #[test]
    fn measures_a_disc_to_a_tenth_of_a_pixel() {
        for (c, r) in [([128.0, 128.0], 120.0), ([250.3, 261.7], 231.4)] {
            let rim = MirrorRim::measure(&disc(512, c, r)).unwrap();
            assert!((rim.radius_px - r).abs() < 0.1, "{rim:?} vs {r}");
            assert!((rim.centre_px[0] - c[0]).abs() < 0.1 && (rim.centre_px[1] - c[1]).abs() < 0.1);
        }
    }

    #[test]
    fn a_black_image_has_no_rim() {
        let img = RgbaImage::from_pixel(64, 64, Rgba([0, 0, 0, 255]));
        let e = MirrorRim::measure(&img).unwrap_err();
        assert!(e.to_string().contains("no mirror rim"), "{e}");
    }
}
