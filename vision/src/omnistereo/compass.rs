//! The visual compass: the robot's rotation between two frames from the angular optic flow of
//! the omnidirectional image, with no iteration (Sect. 1; the paper gives the idea, not the
//! algorithm).
//!
//! Ours: a rotation of the robot by `omega` about the mirror axis turns the whole image by
//! `-omega` (every scene point's bearing drops by `omega`); a translation moves each point by
//! its own parallax, small for a 15 mm step and of opposite signs on the two sides. So the
//! rotation is the angular shift that best aligns the two frames' angular intensity profiles.
//! Each image gives `rings` circles between `inner_fraction` and `outer_fraction` of the rim's
//! radius; on each, the luminance at `samples` azimuths (bilinear), less its mean. The shift maximises the circular cross-correlation summed over
//! every ring of both frames, `C(l) = sum_rings sum_k a[k + l] b[k]`, searched over
//! `|l| <= max_rotation_deg`; a parabola through the peak and its neighbours gives the
//! fraction of a sample. Rings of stronger contrast weigh more (the profiles are not scaled).

use super::numbers::{below, positive};
use super::rim::MirrorRim;
use crate::VisionError;
use image::RgbaImage;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Settings of the visual compass (`[vision.omnistereo.compass]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CompassConfig {
    /// Circles per image.
    pub rings: usize,
    /// Radius of the innermost circle as a fraction of the rim's.
    pub inner_fraction: f64,
    /// Radius of the outermost circle as a fraction of the rim's.
    pub outer_fraction: f64,
    /// Samples on each circle.
    pub samples: usize,
    /// Largest rotation between two frames searched, degrees.
    pub max_rotation_deg: f64,
}

impl Default for CompassConfig {
    fn default() -> Self {
        Self {
            rings: 4,
            inner_fraction: 0.25,
            outer_fraction: 0.95,
            samples: 512,
            max_rotation_deg: 10.0,
        }
    }
}

impl CompassConfig {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), VisionError> {
        positive("compass.max_rotation_deg", self.max_rotation_deg)?;
        if self.rings == 0 || self.samples < 36 {
            return Err(VisionError::InvalidParameter {
                name: "compass.rings, compass.samples",
                value: self.rings.min(self.samples) as f64,
                rule: "need at least one ring of 36 samples",
            });
        }
        if !(0.0 < self.inner_fraction
            && self.inner_fraction <= self.outer_fraction
            && self.outer_fraction < 1.0)
        {
            return Err(VisionError::InvalidParameter {
                name: "compass.inner_fraction",
                value: self.inner_fraction,
                rule: "need 0 < inner_fraction <= outer_fraction < 1",
            });
        }
        below(
            "compass.max_rotation_deg",
            self.max_rotation_deg,
            180.0,
            "must be below 180",
        )
    }
}

/// The angular luminance profiles of one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct AngularProfile {
    samples: usize,
    rings: Vec<Vec<f32>>,
}

/// A rotation the compass read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rotation {
    /// The robot's turn from the earlier frame to this one, counter-clockwise positive, rad.
    pub rotation_rad: f64,
    /// Normalised correlation at the peak (1: the profiles align exactly).
    pub peak: f64,
}

/// Luminance (Rec. 601) at continuous image position `(x, y)` (pixel units, pixel `(u, v)`'s
/// centre at `(u + 0.5, v + 0.5)`), bilinear; `None` where the four pixels are not all inside
/// the image.
fn luminance(raw: &[u8], w: usize, h: usize, x: f64, y: f64) -> Option<f32> {
    let (fx, fy) = (x - 0.5, y - 0.5);
    if !(fx >= 0.0 && fy >= 0.0) {
        return None;
    }
    let (u0, v0) = (fx as usize, fy as usize);
    if u0 + 1 >= w || v0 + 1 >= h {
        return None;
    }
    let (tx, ty) = ((fx - u0 as f64) as f32, (fy - v0 as f64) as f32);
    let luma =
        |i: usize| 0.299 * raw[i] as f32 + 0.587 * raw[i + 1] as f32 + 0.114 * raw[i + 2] as f32;
    let i = 4 * (v0 * w + u0);
    let j = i + 4 * w;
    let top = luma(i) * (1.0 - tx) + luma(i + 4) * tx;
    let bottom = luma(j) * (1.0 - tx) + luma(j + 4) * tx;
    Some(top * (1.0 - ty) + bottom * ty)
}

impl AngularProfile {
    /// The profiles of one frame, from each image and the rim measured in it.
    pub fn capture(images: &[(&RgbaImage, &MirrorRim)], cfg: &CompassConfig) -> Self {
        let n = cfg.samples;
        let trig: Vec<(f64, f64)> = (0..n)
            .map(|k| {
                let a = 2.0 * PI * k as f64 / n as f64;
                (a.cos(), a.sin())
            })
            .collect();
        let mut rings = Vec::with_capacity(images.len() * cfg.rings);
        for (img, rim) in images {
            for j in 0..cfg.rings {
                let f = if cfg.rings == 1 {
                    0.5 * (cfg.inner_fraction + cfg.outer_fraction)
                } else {
                    cfg.inner_fraction
                        + (cfg.outer_fraction - cfg.inner_fraction) * j as f64
                            / (cfg.rings - 1) as f64
                };
                let h = f * rim.radius_px;
                let (w, ht) = (img.width() as usize, img.height() as usize);
                let raw = img.as_raw();
                let [cx, cy] = rim.centre_px;
                // Outside the image (a rim cut by the frame's edge) a sample repeats the last.
                let mut last = 0.0;
                let mut ring: Vec<f32> = trig
                    .iter()
                    .map(|(c, s)| {
                        if let Some(l) = luminance(raw, w, ht, cx + h * c, cy - h * s) {
                            last = l;
                        }
                        last
                    })
                    .collect();
                let mean = ring.iter().sum::<f32>() / n as f32;
                ring.iter_mut().for_each(|x| *x -= mean);
                rings.push(ring);
            }
        }
        Self { samples: n, rings }
    }

    /// The robot's rotation from `earlier` to this frame.
    pub fn rotation_from(
        &self,
        earlier: &AngularProfile,
        cfg: &CompassConfig,
    ) -> Result<Rotation, VisionError> {
        let n = self.samples;
        if earlier.samples != n || earlier.rings.len() != self.rings.len() {
            return Err(VisionError::NotFound(
                "the two frames' profiles have different shapes".into(),
            ));
        }
        let max_lag = ((cfg.max_rotation_deg / 360.0) * n as f64).ceil() as i64;
        let lags: Vec<i64> = (-max_lag..=max_lag).collect();
        let mut corr = vec![0f64; lags.len()];
        let (mut ea, mut eb) = (0f64, 0f64);
        for (a, b) in earlier.rings.iter().zip(&self.rings) {
            ea += a.iter().map(|x| (x * x) as f64).sum::<f64>();
            eb += b.iter().map(|x| (x * x) as f64).sum::<f64>();
            for (c, &l) in corr.iter_mut().zip(&lags) {
                // sum_k a[(k + l) mod n] b[k], in two runs that need no modulo.
                let off = (l.rem_euclid(n as i64)) as usize;
                let head: f32 = a[off..].iter().zip(b).map(|(x, y)| x * y).sum();
                let tail: f32 = a[..off].iter().zip(&b[n - off..]).map(|(x, y)| x * y).sum();
                *c += (head + tail) as f64;
            }
        }
        let norm = (ea * eb).sqrt();
        // Less than a tenth of a grey level of contrast (rms) on every ring: nothing to align.
        let floor = 0.01 * (n * self.rings.len()) as f64;
        if !(ea > floor && eb > floor) {
            return Err(VisionError::NotFound(
                "the images are uniform on every ring: no angular structure to align".into(),
            ));
        }
        let k = (0..corr.len())
            .max_by(|&i, &j| corr[i].total_cmp(&corr[j]))
            .unwrap_or(0);
        let frac = if k > 0 && k + 1 < corr.len() {
            let (y0, y1, y2) = (corr[k - 1], corr[k], corr[k + 1]);
            let den = y0 - 2.0 * y1 + y2;
            if den < 0.0 {
                0.5 * (y0 - y2) / den
            } else {
                0.0
            }
        } else {
            0.0
        };
        Ok(Rotation {
            rotation_rad: (lags[k] as f64 + frac) * 2.0 * PI / n as f64,
            peak: corr[k] / norm,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::rim::synthetic_disc;
    use super::*;
    use image::Rgba;

    /// A disc with a pattern of sectors that depends on azimuth and radius, turned by `turn`
    /// (the robot's rotation: features appear at azimuth - turn).
    fn scene(turn: f64) -> (RgbaImage, MirrorRim) {
        synthetic_disc(|h, a| {
            let g = 120.0
                + 60.0 * (3.0 * (a + turn)).sin()
                + 40.0 * (7.0 * (a + turn) + h / 40.0).cos();
            let g = g.clamp(0.0, 255.0) as u8;
            Rgba([g, g, g, 255])
        })
    }

    #[test]
    fn recovers_known_rotations_to_a_tenth_of_a_degree() {
        let cfg = CompassConfig::default();
        let (a, rim) = scene(0.0);
        let before = AngularProfile::capture(&[(&a, &rim)], &cfg);
        for deg in [0.0, 0.37, -2.9, 6.25] {
            let (b, _) = scene(f64::to_radians(deg));
            let after = AngularProfile::capture(&[(&b, &rim)], &cfg);
            let r = after.rotation_from(&before, &cfg).unwrap();
            assert!(
                (r.rotation_rad.to_degrees() - deg).abs() < 0.1,
                "{deg}: read {}",
                r.rotation_rad.to_degrees()
            );
            assert!(r.peak > 0.9);
        }
    }

    #[test]
    fn a_uniform_image_has_no_rotation() {
        let rim = MirrorRim {
            centre_px: [32.0, 32.0],
            radius_px: 30.0,
            points: 0,
        };
        let img = RgbaImage::from_pixel(64, 64, Rgba([100, 100, 100, 255]));
        let cfg = CompassConfig::default();
        let p = AngularProfile::capture(&[(&img, &rim)], &cfg);
        assert!(p.rotation_from(&p, &cfg).is_err());
    }
}
