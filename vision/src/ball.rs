//! The ball in one camera image: its colour, the blob it makes, and where it lies on the floor.
//!
//! A pixel is the ball's when its chromaticity is the ball's (red well above green, green well
//! above blue: the league's orange, whatever the shading); the largest 8-connected blob of such
//! pixels is the ball. Its bearing is the azimuth of the blob's centroid about the camera axis.
//!
//! **Range from where the ball meets the floor.** A sphere of radius `rho` seen from a point
//! fills a cone symmetric about the ray to its centre, so in the vertical plane through the
//! camera axis the ray to the centre bisects the blob's two edge rays: with `e_in`, `e_out` the
//! elevations (from the calibration's elevation column) at the blob's inner and outer image
//! radii, the centre ray has `e_c = (e_in + e_out) / 2`, meets the floor at `f(R_c)` (the
//! image-to-floor map of eqs. (1)-(4) of the corner paper, `R_c` the radius of elevation `e_c`),
//! and passes the height `rho` of the centre at
//!
//! ```text
//! D = f(R_c) - rho / tan(-e_c)
//! ```
//!
//! from the camera axis. A calibration without the elevation column gives `D = f(R_in)`, the
//! floor point just short of the contact point (low by `rho tan(alpha / 2)`, `alpha` the ray's
//! depression: 2 mm at 1 m for E1's mirror). A pinhole camera does the same with its own rays:
//! the centre ray bisects the rays of the blob's top and bottom edges and is cut at the height
//! `rho`. The paper has no ball; this construction and its uncertainties are ours.

use crate::calibration::RadialCalibration;
use crate::forward::ForwardCamera;
use image::RgbaImage;
use nalgebra::{Point2, Vector2, Vector3};
use serde::{Deserialize, Serialize};

/// The ball's colour as chromaticity bounds, so that shading does not change it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BallColor {
    /// The red channel at least this (darker pixels are too noisy to judge).
    pub min_red: u8,
    /// Green over red within `[lo, hi]` (orange 0.43; the yellow goal 0.85, its darkest
    /// noisy pixels down to 0.67; red 0).
    pub green_over_red: [f64; 2],
    /// Blue over red at most this.
    pub max_blue_over_red: f64,
}

impl Default for BallColor {
    /// The league's orange ball ([255, 110, 20]) with room for noise and shading.
    fn default() -> Self {
        Self {
            min_red: 60,
            green_over_red: [0.22, 0.6],
            max_blue_over_red: 0.4,
        }
    }
}

impl BallColor {
    /// Whether pixel `p` is ball-coloured.
    pub fn contains(&self, p: [u8; 3]) -> bool {
        if p[0] < self.min_red {
            return false;
        }
        let (r, g, b) = (f32::from(p[0]), f32::from(p[1]), f32::from(p[2]));
        g >= self.green_over_red[0] as f32 * r
            && g <= self.green_over_red[1] as f32 * r
            && b <= self.max_blue_over_red as f32 * r
    }
}

/// Settings of the ball detector (`[vision.ball]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BallConfig {
    /// The ball's colour.
    pub color: BallColor,
    /// The ball's radius, mm (the league's: 21.5).
    pub radius_mm: f64,
    /// A blob of fewer pixels is "too small" to be taken for the ball.
    pub min_pixels: usize,
}

impl Default for BallConfig {
    fn default() -> Self {
        Self {
            color: BallColor::default(),
            radius_mm: 21.5,
            min_pixels: 1,
        }
    }
}

/// The ball as one image shows it, in the robot frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BallSighting {
    /// Its centre on the floor, robot frame (x forward, y left), mm.
    pub position_mm: Point2<f64>,
    /// Distance of its centre from the robot's centre, mm.
    pub range_mm: f64,
    /// Direction of its centre from the robot's centre, counter-clockwise from forward, rad.
    pub bearing_rad: f64,
    /// One-sigma error of the range, mm (half a pixel at each edge of the blob, through the
    /// calibration's slope).
    pub range_sigma_mm: f64,
    /// One-sigma error of the bearing, rad (the centroid's quantisation).
    pub bearing_sigma_rad: f64,
    /// Pixels in the blob.
    pub pixels: usize,
}

/// Why an image shows no ball.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BallMiss {
    /// No pixel of the ball's colour where the camera sees the floor.
    #[error("no ball-coloured pixel in view")]
    NoBallColour,
    /// The largest blob is smaller than the detector takes.
    #[error("too small: {pixels} px, need {need}")]
    TooSmall {
        /// Its pixels.
        pixels: usize,
        /// The least the detector takes.
        need: usize,
    },
    /// The blob's rays do not reach the floor through the calibration.
    #[error("blob beyond the calibration's floor horizon")]
    OffFloor,
}

/// A blob of ball-coloured pixels: each pixel's coordinates `(u, v)` (column, row).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Blob {
    /// Its pixels.
    pub pixels: Vec<[u32; 2]>,
}

/// The largest 8-connected blob of ball-coloured pixels among those `keep` accepts (by column
/// and row), or `None` when no pixel is ball-coloured.
pub fn largest_blob(
    img: &RgbaImage,
    color: &BallColor,
    keep: impl Fn(u32, u32) -> bool,
) -> Option<Blob> {
    let (w, h) = img.dimensions();
    let mut mask: Vec<bool> = img
        .enumerate_pixels()
        .map(|(u, v, p)| color.contains([p[0], p[1], p[2]]) && keep(u, v))
        .collect();
    let mut best: Option<Blob> = None;
    let mut stack = Vec::new();
    for start in 0..mask.len() {
        if !mask[start] {
            continue;
        }
        mask[start] = false;
        stack.push(start);
        let mut blob = Blob::default();
        while let Some(i) = stack.pop() {
            let (u, v) = ((i % w as usize) as i64, (i / w as usize) as i64);
            blob.pixels.push([u as u32, v as u32]);
            for (du, dv) in NEIGHBOURS {
                let (nu, nv) = (u + du, v + dv);
                if nu >= 0 && nv >= 0 && nu < i64::from(w) && nv < i64::from(h) {
                    let j = nv as usize * w as usize + nu as usize;
                    if mask[j] {
                        mask[j] = false;
                        stack.push(j);
                    }
                }
            }
        }
        if best
            .as_ref()
            .is_none_or(|b| blob.pixels.len() > b.pixels.len())
        {
            best = Some(blob);
        }
    }
    best
}

/// The eight neighbours of a pixel.
const NEIGHBOURS: [(i64, i64); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

/// The ball in a mirror camera's image, through its image-to-floor calibration.
pub fn detect_mirror(
    img: &RgbaImage,
    cal: &RadialCalibration,
    config: &BallConfig,
) -> Result<BallSighting, BallMiss> {
    let horizon = cal.horizon_px.min(cal.max_radius_px());
    let keep = |u: u32, v: u32| {
        let (x, y) = cal.image_coords(f64::from(u), f64::from(v));
        x.hypot(y) < horizon
    };
    let blob = largest_blob(img, &config.color, keep).ok_or(BallMiss::NoBallColour)?;
    check_size(&blob, config)?;
    let coords: Vec<(f64, f64)> = blob
        .pixels
        .iter()
        .map(|p| cal.image_coords(f64::from(p[0]), f64::from(p[1])))
        .collect();
    let radii = coords.iter().map(|(x, y)| x.hypot(*y));
    let r_in = radii.clone().fold(f64::INFINITY, f64::min) - 0.5;
    let r_out = (radii.fold(0.0, f64::max) + 0.5).min(horizon);
    let (sx, sy) = coords
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    let phi = sy.atan2(sx);
    let axis = |dr: f64| mirror_centre_distance(cal, r_in.max(0.0) + dr, r_out + dr, config);
    let d = axis(0.0).ok_or(BallMiss::OffFloor)?;
    // Half a pixel at each edge moves the centre ray by about half a pixel over sqrt(2).
    let slope = axis(0.5).map_or(0.0, |d2| (d2 - d).abs() * 2.0);
    let centroid_px = (sx / coords.len() as f64).hypot(sy / coords.len() as f64);
    let on_axis = Vector2::new(phi.cos(), phi.sin()) * d;
    Ok(sighting(
        Point2::from(cal.mount_mm) + on_axis,
        slope * 0.5 / 2f64.sqrt(),
        0.5 / (centroid_px.max(1.0) * (blob.pixels.len() as f64).sqrt()),
        blob.pixels.len(),
    ))
}

/// Distance of the ball's centre from the camera axis, from the blob's inner and outer image
/// radii (the module's construction); `None` beyond the calibration.
fn mirror_centre_distance(
    cal: &RadialCalibration,
    r_in: f64,
    r_out: f64,
    config: &BallConfig,
) -> Option<f64> {
    if cal.elevation.len() < 2 {
        return cal.floor_distance_mm(r_in);
    }
    let e_c = 0.5 * (cal.elevation_rad(r_in)? + cal.elevation_rad(r_out)?);
    let r_c = cal.radius_at_elevation_px(e_c)?;
    let floor = cal.floor_distance_mm(r_c)?;
    (e_c < 0.0).then(|| floor - config.radius_mm / (-e_c).tan())
}

/// The ball in a forward pinhole camera's image.
pub fn detect_forward(
    img: &RgbaImage,
    cam: &ForwardCamera,
    config: &BallConfig,
) -> Result<BallSighting, BallMiss> {
    let blob = largest_blob(img, &config.color, |_, _| true).ok_or(BallMiss::NoBallColour)?;
    check_size(&blob, config)?;
    let n = blob.pixels.len() as f64;
    let x = blob.pixels.iter().map(|p| f64::from(p[0])).sum::<f64>() / n;
    let top = blob.pixels.iter().map(|p| p[1]).min().unwrap_or(0);
    let bottom = blob.pixels.iter().map(|p| p[1]).max().unwrap_or(0);
    let at = |dy: f64| {
        let d = cam.direction(x, f64::from(top) - 0.5 + dy)
            + cam.direction(x, f64::from(bottom) + 0.5 + dy);
        centre_on_ray(cam, &d, config.radius_mm)
    };
    let p = at(0.0).ok_or(BallMiss::OffFloor)?;
    let slope = at(0.5).map_or(0.0, |q| (q - p).norm() * 2.0);
    Ok(sighting(
        p,
        slope * 0.5 / 2f64.sqrt(),
        0.5 / (cam.focal_px * n.sqrt()),
        blob.pixels.len(),
    ))
}

/// Where the ray from the pinhole along `d` is at the height of the ball's centre.
fn centre_on_ray(cam: &ForwardCamera, d: &Vector3<f64>, radius_mm: f64) -> Option<Point2<f64>> {
    let d = d.normalize();
    (d.z < -1e-6).then(|| {
        let t = (cam.height_mm - radius_mm) / -d.z;
        Point2::new(cam.mount_mm[0] + t * d.x, cam.mount_mm[1] + t * d.y)
    })
}

/// A blob too small to be the ball is a miss.
fn check_size(blob: &Blob, config: &BallConfig) -> Result<(), BallMiss> {
    if blob.pixels.len() < config.min_pixels {
        return Err(BallMiss::TooSmall {
            pixels: blob.pixels.len(),
            need: config.min_pixels,
        });
    }
    Ok(())
}

/// The sighting of a ball centred at `p` (robot frame).
fn sighting(
    p: Point2<f64>,
    range_sigma_mm: f64,
    bearing_sigma_rad: f64,
    pixels: usize,
) -> BallSighting {
    BallSighting {
        position_mm: p,
        range_mm: p.coords.norm(),
        bearing_rad: p.y.atan2(p.x),
        range_sigma_mm,
        bearing_sigma_rad,
        pixels,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgba;

    #[test]
    fn orange_is_the_ball_and_the_field_colours_are_not() {
        let c = BallColor::default();
        assert!(c.contains([255, 110, 20]));
        // Shaded to a third, with noise.
        assert!(c.contains([88, 40, 9]));
        for other in [
            [117, 79, 13],
            [30, 130, 55],
            [240, 240, 240],
            [235, 200, 20],
            [25, 60, 220],
            [200, 0, 0],
            [20, 20, 20],
            [40, 30, 10],
        ] {
            assert!(!c.contains(other), "{other:?}");
        }
    }

    #[test]
    fn the_largest_blob_wins() {
        let mut img = RgbaImage::from_pixel(20, 10, Rgba([30, 130, 55, 255]));
        for (u, v) in [(2, 2), (3, 3), (4, 3), (12, 5)] {
            img.put_pixel(u, v, Rgba([255, 110, 20, 255]));
        }
        let blob = largest_blob(&img, &BallColor::default(), |_, _| true).unwrap();
        assert_eq!(blob.pixels.len(), 3);
        let none = largest_blob(&img, &BallColor::default(), |u, _| u > 15);
        assert!(none.is_none());
    }

    /// A synthetic single-viewpoint sensor: viewpoint 200 mm up, image radius `R` sees the
    /// floor at `r = 10 R` (so the elevation is `-atan(200 / 10 R)`).
    fn synthetic() -> RadialCalibration {
        let samples: Vec<[f64; 2]> = (0..=100).map(|k| [k as f64, 10.0 * k as f64]).collect();
        let elevation = (1..=100)
            .map(|k| [k as f64, -(200.0 / (10.0 * k as f64)).atan()])
            .collect();
        RadialCalibration {
            sensor: "omni".into(),
            width_px: 201,
            height_px: 201,
            principal_point_px: [100.5, 100.5],
            mount_mm: [0.0, 0.0],
            samples,
            horizon_px: 100.0,
            elevation,
            fit: None,
        }
    }

    #[test]
    fn a_painted_ball_is_found_at_its_range_and_bearing() {
        let cal = synthetic();
        let mut img = RgbaImage::from_pixel(201, 201, Rgba([30, 130, 55, 255]));
        // The ball at 600 mm on bearing 30 degrees: its edge rays by the sphere's tangents.
        let (d, rho, bearing) = (600.0f64, 21.5f64, 30f64.to_radians());
        let alpha_c = (200.0 - rho).atan2(d);
        let half = (rho / (200.0 - rho).hypot(d)).asin();
        let r_of = |alpha: f64| 200.0 / alpha.tan() / 10.0;
        let (r_in, r_out) = (r_of(alpha_c + half), r_of(alpha_c - half));
        for v in 0..201u32 {
            for u in 0..201u32 {
                let (x, y) = cal.image_coords(f64::from(u), f64::from(v));
                let (r, phi) = (x.hypot(y), y.atan2(x));
                if r >= r_in && r <= r_out && (phi - bearing).abs() < 0.05 {
                    img.put_pixel(u, v, Rgba([255, 110, 20, 255]));
                }
            }
        }
        let s = detect_mirror(&img, &cal, &BallConfig::default()).unwrap();
        assert!((s.range_mm - d).abs() < 0.03 * d, "{s:?}");
        assert!((s.bearing_rad - bearing).abs() < 1f64.to_radians(), "{s:?}");
        assert!(s.range_sigma_mm > 0.0 && s.range_sigma_mm < 30.0, "{s:?}");
    }

    #[test]
    fn a_field_without_the_ball_gives_the_reason() {
        let cal = synthetic();
        let img = RgbaImage::from_pixel(201, 201, Rgba([30, 130, 55, 255]));
        let miss = detect_mirror(&img, &cal, &BallConfig::default()).unwrap_err();
        assert_eq!(miss, BallMiss::NoBallColour);
        let mut img = img;
        img.put_pixel(120, 100, Rgba([255, 110, 20, 255]));
        let config = BallConfig {
            min_pixels: 3,
            ..BallConfig::default()
        };
        let miss = detect_mirror(&img, &cal, &config).unwrap_err();
        assert_eq!(miss, BallMiss::TooSmall { pixels: 1, need: 3 });
        assert_eq!(miss.to_string(), "too small: 1 px, need 3");
    }
}
