//! A forward camera tilted down at the floor on a small robot (Ahmed, Saatchi and Caparrelli,
//! "Vision based obstacle avoidance and odometry for swarms of small size robots"): obstacle
//! avoidance by ground segmentation (Sect. 2.1.1) and by Horn-Schunck optical flow
//! (Sect. 2.1.2), rotation from scan-line intensity profiles (Sect. 2.2.1) and translation from
//! Harris corners tracked by Lucas-Kanade (Sect. 2.2.2) or matched by normalised
//! cross-correlation (Sect. 2.2.3).
//!
//! Images are grey [`Grey`] planes of `f32` levels (0-255); generic filters (smoothing,
//! gradients, dilation) come from `imageproc`.

pub mod camera;
pub mod features;
pub mod flow;
pub mod grey;
pub mod ground;
pub mod harris;
pub mod lk;
pub mod ncc;
pub mod odometry;
pub mod scanline;

pub use camera::ForwardCamera;
pub use features::{FeatureConfig, FeatureMotion, FeatureTracks, TrackingError};
pub use flow::{FlowBalance, FlowConfig, FlowField, horn_schunck, reduce};
pub use grey::{Grey, bilinear, grey};
pub use ground::{GroundConfig, GroundSegmenter, GroundView};
pub use harris::{Corner, HarrisConfig, harris_corners};
pub use lk::{LkConfig, pyramid, track_lk};
pub use ncc::{NccConfig, NccMatch, match_ncc};
pub use odometry::{FeatureMethod, ForwardOdometry, OdometryConfig, OdometryStep};
pub use scanline::{ScanLine, ScanLineConfig};

#[cfg(test)]
pub(crate) mod testing {
    use super::Grey;
    use image::Luma;

    /// The E6 camera: 160 x 120, f 138.6, 100 mm up, tilted 25 degrees down, on the axle.
    pub fn camera() -> super::ForwardCamera {
        super::ForwardCamera {
            sensor: "front".into(),
            width_px: 160,
            height_px: 120,
            cx_px: 80.0,
            cy_px: 60.0,
            focal_px: 138.6,
            height_mm: 100.0,
            tilt_rad: -25f64.to_radians(),
            mount_mm: [0.0, 0.0],
        }
    }

    /// A smooth texture of a few sinusoids and blobs, shifted by `(dx, dy)` (its content moves
    /// right and down by that much).
    pub fn texture(w: u32, h: u32, dx: f64, dy: f64) -> Grey {
        Grey::from_fn(w, h, |x, y| {
            let (u, v) = (x as f64 - dx, y as f64 - dy);
            let s = (u * 0.31).sin() * (v * 0.23).cos()
                + 0.6 * (u * 0.11 + v * 0.17).sin()
                + 0.4 * ((u - 40.0).powi(2) / 60.0 + (v - 30.0).powi(2) / 90.0).cos();
            Luma([(128.0 + 45.0 * s) as f32])
        })
    }

    /// What `camera` sees of a light floor with dark squares (20-60 mm, one in each 150 mm
    /// cell) from the robot pose `(x_mm, y_mm, heading_rad)`, 3 x 3 samples a pixel.
    pub fn floor_view(
        camera: &super::ForwardCamera,
        x_mm: f64,
        y_mm: f64,
        heading_rad: f64,
    ) -> Grey {
        let pose = nalgebra::Isometry2::new(nalgebra::Vector2::new(x_mm, y_mm), heading_rad);
        let dark = |x: f64, y: f64| -> bool {
            let cell = 150.0;
            let (i, j) = ((x / cell).floor() as i64, (y / cell).floor() as i64);
            let h = (i.wrapping_mul(73_856_093) ^ j.wrapping_mul(19_349_663)).unsigned_abs();
            let size = 20.0 + (h % 41) as f64;
            let (jx, jy) = (
                ((h / 41) % 41) as f64 - 20.0,
                ((h / 1681) % 41) as f64 - 20.0,
            );
            let (cx, cy) = ((i as f64 + 0.5) * cell + jx, (j as f64 + 0.5) * cell + jy);
            (x - cx).abs() < 0.5 * size && (y - cy).abs() < 0.5 * size
        };
        Grey::from_fn(camera.width_px, camera.height_px, |px, py| {
            let mut sum = 0.0;
            for sy in 0..3 {
                for sx in 0..3 {
                    let (u, v) = (
                        px as f64 + (sx as f64 - 1.0) / 3.0,
                        py as f64 + (sy as f64 - 1.0) / 3.0,
                    );
                    sum += match camera.floor_point(u, v) {
                        Some(p) => {
                            let w = pose * p;
                            if dark(w.x, w.y) { 40.0 } else { 210.0 }
                        }
                        None => 120.0,
                    };
                }
            }
            Luma([sum as f32 / 9.0])
        })
    }

    /// Dark squares on a light ground, shifted by `(dx, dy)`, each pixel shaded by the exact
    /// fraction of it a square covers.
    pub fn squares(w: u32, h: u32, dx: f64, dy: f64) -> Grey {
        let squares = [
            (20.0, 18.0, 9.0),
            (60.0, 40.0, 12.0),
            (95.0, 22.0, 7.0),
            (40.0, 70.0, 10.0),
            (110.0, 75.0, 11.0),
        ];
        let overlap = |p: f64, lo: f64, hi: f64| ((p + 0.5).min(hi) - (p - 0.5).max(lo)).max(0.0);
        Grey::from_fn(w, h, |x, y| {
            let dark: f64 = squares
                .iter()
                .map(|&(cx, cy, r)| {
                    overlap(x as f64, cx - r + dx, cx + r + dx)
                        * overlap(y as f64, cy - r + dy, cy + r + dy)
                })
                .sum();
            Luma([(210.0 - 170.0 * dark.min(1.0)) as f32])
        })
    }
}
