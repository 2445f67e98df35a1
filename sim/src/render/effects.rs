//! What a real camera does to the traced image (`[robot.sensors.effects]`), in the order light
//! meets it: the scene's light level (`illumination`), motion blur over the exposure
//! (`exposure_s`: the frame is the mean of sub-frames traced at the poses the robot passed
//! through while the shutter was open), vignetting (the brightness falls as
//! `1 - vignetting (r / r_rim)^2`, `r_rim` the largest circle about the principal point inside
//! the image), defocus (a Gaussian blur of `defocus_px` sigma), the sensor's noise (the same
//! counter-based draws as without effects), the exposure scale `gain` with clipping at 255,
//! and JPEG compression at `jpeg_quality`.
//!
//! Every step after tracing runs on the CPU on the traced frames, so the GPU and the CPU
//! renderer give the same frame wherever they trace the same pixels. All effects off (the
//! default) leaves the frame exactly as before.

use super::error::RenderError;
use super::noise::{self, FrameNoise};
use image::RgbaImage;
use nalgebra::{Isometry2, Vector2};
use omniloop_problem::{Problem, Problems};
use serde::{Deserialize, Serialize};

/// A sensor's camera effects; the default is a perfect camera.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CameraEffects {
    /// Exposure time (s): the frame integrates the scene while the robot moves (0: a
    /// snapshot).
    pub exposure_s: f64,
    /// Sub-frames traced over the exposure.
    pub exposure_samples: u32,
    /// Gaussian blur sigma (px) of a defocused lens (0: sharp).
    pub defocus_px: f64,
    /// Fraction of the brightness lost at the rim of the image circle (0: none).
    pub vignetting: f64,
    /// Exposure scale applied to the noisy signal, clipped at 255 (1: none).
    pub gain: f64,
    /// The scene's light level (1: as lit; 0.5: a room half as bright).
    pub illumination: f64,
    /// JPEG quality 1-100 of the delivered frames (0: raw frames).
    pub jpeg_quality: u8,
}

impl Default for CameraEffects {
    fn default() -> Self {
        Self {
            exposure_s: 0.0,
            exposure_samples: 8,
            defocus_px: 0.0,
            vignetting: 0.0,
            gain: 1.0,
            illumination: 1.0,
            jpeg_quality: 0,
        }
    }
}

impl CameraEffects {
    /// Whether the camera is perfect (no step below changes a frame).
    pub fn is_off(&self) -> bool {
        let d = Self::default();
        self.exposure_s == 0.0
            && self.defocus_px == 0.0
            && self.vignetting == 0.0
            && self.gain == d.gain
            && self.illumination == d.illumination
            && self.jpeg_quality == 0
    }

    /// How many sub-frames a frame is traced as.
    pub fn sub_frames(&self) -> usize {
        if self.exposure_s > 0.0 {
            self.exposure_samples.max(1) as usize
        } else {
            1
        }
    }

    /// Its values that break a rule, each naming its key.
    pub fn problems(&self) -> Vec<Problem> {
        let mut p = Problems::new();
        let mut check = |key: &str, v: f64, ok: bool, rule: &str| {
            if !(v.is_finite() && ok) {
                p.fail(key, format!("must be {rule} (got {v})"));
            }
        };
        check(
            "exposure_s",
            self.exposure_s,
            self.exposure_s >= 0.0,
            ">= 0",
        );
        check(
            "defocus_px",
            self.defocus_px,
            (0.0..=20.0).contains(&self.defocus_px),
            "0..=20",
        );
        check(
            "vignetting",
            self.vignetting,
            (0.0..=1.0).contains(&self.vignetting),
            "0..=1",
        );
        check("gain", self.gain, self.gain > 0.0, "> 0");
        check(
            "illumination",
            self.illumination,
            self.illumination >= 0.0,
            ">= 0",
        );
        if !(1..=64).contains(&self.exposure_samples) {
            p.fail(
                "exposure_samples",
                format!("must be 1..=64 (got {})", self.exposure_samples),
            );
        }
        if self.jpeg_quality > 100 {
            p.fail(
                "jpeg_quality",
                format!("must be 0 (raw) or 1..=100 (got {})", self.jpeg_quality),
            );
        }
        p.into_vec()
    }
}

/// `pose` moved on for `dt_s` (negative: back) at `velocity_mm_s` (world frame) and
/// `omega_rad_s`.
pub fn pose_after(
    pose: &Isometry2<f64>,
    velocity_mm_s: Vector2<f64>,
    omega_rad_s: f64,
    dt_s: f64,
) -> Isometry2<f64> {
    Isometry2::new(
        pose.translation.vector + velocity_mm_s * dt_s,
        pose.rotation.angle() + omega_rad_s * dt_s,
    )
}

/// The robot's poses while the shutter is open, for `samples` sub-frames: the exposure ends at
/// `pose` and lasts `exposure_s`, the robot moving at `velocity_mm_s` (world frame) and
/// `omega_rad_s`; sub-frame `j` is at the middle of its slice, `s_j = exposure (j + 0.5) / n`
/// before the end. Without exposure, `pose` alone.
pub fn exposure_poses(
    pose: &Isometry2<f64>,
    velocity_mm_s: Vector2<f64>,
    omega_rad_s: f64,
    effects: &CameraEffects,
) -> Vec<Isometry2<f64>> {
    let n = effects.sub_frames();
    if effects.exposure_s <= 0.0 {
        return vec![*pose];
    }
    (0..n)
        .map(|j| {
            let s = effects.exposure_s * (j as f64 + 0.5) / n as f64;
            pose_after(pose, velocity_mm_s, omega_rad_s, -s)
        })
        .collect()
}

/// `img` as the camera delivers it: JPEG-compressed at `quality` and decoded again (0: raw).
pub fn compress(img: RgbaImage, quality: u8) -> Result<RgbaImage, RenderError> {
    if quality == 0 {
        return Ok(img);
    }
    let rgb = image::DynamicImage::ImageRgba8(img).to_rgb8();
    let mut bytes = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, quality.min(100))
        .encode_image(&rgb)
        .map_err(|e| RenderError::Invalid(format!("JPEG encoding: {e}")))?;
    let back = image::load_from_memory_with_format(&bytes, image::ImageFormat::Jpeg)
        .map_err(|e| RenderError::Invalid(format!("JPEG decoding: {e}")))?;
    Ok(back.to_rgba8())
}

/// The frame of `sub_frames` (clean traced frames, packed RGBA8, all of one sensor of
/// `width` x `height` with its principal point at `principal_px`) through `effects`, with
/// `noise`: RGBA bytes.
pub fn develop(
    effects: &CameraEffects,
    sub_frames: &[Vec<u32>],
    size: [u32; 2],
    principal_px: [f64; 2],
    noise: Option<FrameNoise>,
) -> Vec<u8> {
    let [w, h] = size.map(|v| v as usize);
    let n = w * h;
    // Light: the mean of the sub-frames, times the scene's light level and the vignetting.
    let mut light = vec![[0f32; 3]; n];
    let k = effects.illumination as f32 / sub_frames.len().max(1) as f32;
    for frame in sub_frames {
        for (acc, p) in light.iter_mut().zip(frame) {
            let b = p.to_le_bytes();
            for c in 0..3 {
                acc[c] += b[c] as f32;
            }
        }
    }
    let [cx, cy] = principal_px;
    let rim = cx.min(cy).min(w as f64 - cx).min(h as f64 - cy).max(1.0);
    for (i, acc) in light.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64 + 0.5 - cx, (i / w) as f64 + 0.5 - cy);
        let r2 = (x * x + y * y) / (rim * rim);
        let f = k * (1.0 - effects.vignetting * r2).max(0.0) as f32;
        acc.iter_mut().for_each(|v| *v *= f);
    }
    if effects.defocus_px > 0.0 {
        gaussian_blur(&mut light, w, h, effects.defocus_px);
    }
    // The sensor: quantised, its noise, the gain, clipped.
    let packed: Vec<u32> = light
        .iter()
        .map(|p| {
            let q = p.map(|v| v.round().clamp(0.0, 255.0) as u8);
            u32::from_le_bytes([q[0], q[1], q[2], 255])
        })
        .collect();
    let mut rgba = vec![0u8; n * 4];
    match noise {
        Some(fnz) => noise::apply(&packed, fnz, &mut rgba),
        None => {
            for (p, out) in packed.iter().zip(rgba.chunks_exact_mut(4)) {
                out.copy_from_slice(&p.to_le_bytes());
            }
        }
    }
    if effects.gain != 1.0 {
        let g = effects.gain as f32;
        for px in rgba.chunks_exact_mut(4) {
            for v in &mut px[..3] {
                *v = (*v as f32 * g).round().clamp(0.0, 255.0) as u8;
            }
        }
    }
    rgba
}

/// Blurs `img` (`w` x `h`, row-major) with a Gaussian of `sigma` px: separable, the kernel
/// cut at 3 sigma and normalised, the edges clamped.
pub fn gaussian_blur(img: &mut [[f32; 3]], w: usize, h: usize, sigma: f64) {
    let radius = (3.0 * sigma).ceil() as isize;
    let weights: Vec<f32> = (-radius..=radius)
        .map(|d| (-(d * d) as f64 / (2.0 * sigma * sigma)).exp() as f32)
        .collect();
    let total: f32 = weights.iter().sum();
    let kernel: Vec<f32> = weights.iter().map(|v| v / total).collect();
    let pass = |src: &[[f32; 3]], step: (isize, isize)| -> Vec<[f32; 3]> {
        let mut out = vec![[0f32; 3]; src.len()];
        for y in 0..h as isize {
            for x in 0..w as isize {
                let mut acc = [0f32; 3];
                for (j, kv) in kernel.iter().enumerate() {
                    let d = j as isize - radius;
                    let sx = (x + d * step.0).clamp(0, w as isize - 1);
                    let sy = (y + d * step.1).clamp(0, h as isize - 1);
                    let s = src[(sy as usize) * w + sx as usize];
                    for c in 0..3 {
                        acc[c] += kv * s[c];
                    }
                }
                out[(y as usize) * w + x as usize] = acc;
            }
        }
        out
    };
    let across = pass(img, (1, 0));
    let down = pass(&across, (0, 1));
    img.copy_from_slice(&down);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn packed(level: u8) -> u32 {
        u32::from_le_bytes([level, level, level, 255])
    }

    #[test]
    fn all_off_leaves_the_frame_as_traced() {
        let frame: Vec<u32> = (0..64u32 * 48).map(|i| packed((i % 251) as u8)).collect();
        let e = CameraEffects::default();
        assert!(e.is_off());
        let out = develop(
            &e,
            std::slice::from_ref(&frame),
            [64, 48],
            [32.0, 24.0],
            None,
        );
        let back: Vec<u32> = out
            .chunks_exact(4)
            .map(|p| u32::from_le_bytes([p[0], p[1], p[2], p[3]]))
            .collect();
        assert_eq!(back, frame);
    }

    #[test]
    fn a_blurred_step_edge_follows_the_gaussians_integral() {
        // A vertical step from 0 to 200 between columns 31 and 32; after a blur of sigma 2 px
        // the column at distance d from the edge is 200 Phi(d / sigma).
        let (w, h) = (64, 16);
        let frame: Vec<u32> = (0..w * h)
            .map(|i| packed(if i % w >= 32 { 200 } else { 0 }))
            .collect();
        let e = CameraEffects {
            defocus_px: 2.0,
            ..CameraEffects::default()
        };
        let out = develop(&e, &[frame], [w as u32, h as u32], [32.0, 8.0], None);
        let row = 8 * w;
        let phi = |z: f64| 0.5 * (1.0 + erf(z / std::f64::consts::SQRT_2));
        for col in 24..40 {
            let d = col as f64 + 0.5 - 32.0;
            let want = 200.0 * phi(d / 2.0);
            let got = out[(row + col) * 4] as f64;
            assert!((got - want).abs() <= 1.5, "column {col}: {got} vs {want}");
        }
        // 10-90% rise: 2 x 1.2816 sigma = 5.1 px (sharp: 1 px).
        let rise = (0..w)
            .filter(|&c| (20..=180).contains(&out[(row + c) * 4]))
            .count();
        assert!((4..=6).contains(&rise), "{rise}");
    }

    #[test]
    fn vignetting_lowers_the_rim_by_its_fraction() {
        let (w, h) = (100, 80);
        let frame = vec![packed(200); w * h];
        let e = CameraEffects {
            vignetting: 0.3,
            ..CameraEffects::default()
        };
        let out = develop(&e, &[frame], [w as u32, h as u32], [50.0, 40.0], None);
        let at = |x: usize, y: usize| out[(y * w + x) * 4] as f64;
        // The centre keeps its level; on the rim circle (radius 40 px) 30% is lost.
        assert!((at(50, 40) - 200.0).abs() <= 1.0);
        assert!((at(50, 0) - 200.0 * (1.0 - 0.3 * (39.5f64 / 40.0).powi(2))).abs() <= 1.0);
        assert!((at(10, 40) - 200.0 * (1.0 - 0.3 * (39.5f64 / 40.0).powi(2))).abs() <= 1.0);
    }

    #[test]
    fn gain_and_illumination_scale_and_clip() {
        let frame = vec![packed(100); 16];
        let dim = CameraEffects {
            illumination: 0.5,
            ..CameraEffects::default()
        };
        assert_eq!(
            develop(&dim, std::slice::from_ref(&frame), [4, 4], [2.0, 2.0], None)[0],
            50
        );
        let bright = CameraEffects {
            gain: 3.0,
            ..CameraEffects::default()
        };
        assert_eq!(develop(&bright, &[frame], [4, 4], [2.0, 2.0], None)[0], 255);
    }

    /// The error function (Abramowitz and Stegun 7.1.26, |error| < 1.5e-7).
    fn erf(x: f64) -> f64 {
        let t = 1.0 / (1.0 + 0.327_591_1 * x.abs());
        let y = 1.0
            - (((((1.061_405_429 * t - 1.453_152_027) * t) + 1.421_413_741) * t - 0.284_496_736)
                * t
                + 0.254_829_592)
                * t
                * (-x * x).exp();
        y.copysign(x)
    }
}
