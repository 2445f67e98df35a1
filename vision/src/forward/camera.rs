//! The forward camera as the robot knows it: a pinhole at a known height, tilted down by a
//! known angle, so that every pixel below the horizon sees one point of the floor (the floor
//! homography) and every pixel one direction (azimuth, elevation) about the camera.

use nalgebra::{Point2, Vector3};
use serde::{Deserialize, Serialize};

/// A pinhole camera looking forward and down from the robot.
///
/// Pixel coordinates `(x, y)` are continuous with pixel `(i, j)`'s centre at `(i, j)`; the ray
/// of `(x, y)` goes through `X = x + 0.5 - cx` right and `Y = cy - (y + 0.5)` up of the
/// principal point at focal length `f`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ForwardCamera {
    /// The camera's name.
    pub sensor: String,
    /// Image width, px.
    pub width_px: u32,
    /// Image height, px.
    pub height_px: u32,
    /// Principal point from the left edge, px.
    pub cx_px: f64,
    /// Principal point from the top edge, px.
    pub cy_px: f64,
    /// Focal length, px.
    pub focal_px: f64,
    /// Height of the pinhole above the floor, mm.
    pub height_mm: f64,
    /// Elevation of the optical axis, rad (negative looks down).
    pub tilt_rad: f64,
    /// Where the pinhole stands in the robot frame (x forward, y left), mm.
    pub mount_mm: [f64; 2],
}

impl ForwardCamera {
    /// Forward, right and up unit vectors of the camera in the robot frame.
    fn basis(&self) -> [Vector3<f64>; 3] {
        let (st, ct) = self.tilt_rad.sin_cos();
        let forward = Vector3::new(ct, 0.0, st);
        let right = Vector3::new(0.0, -1.0, 0.0);
        [forward, right, right.cross(&forward)]
    }

    /// The unit direction (robot frame, z up) of pixel coordinates `(x, y)`.
    pub fn direction(&self, x: f64, y: f64) -> Vector3<f64> {
        let [f, r, u] = self.basis();
        let (xx, yy) = (x + 0.5 - self.cx_px, self.cy_px - (y + 0.5));
        (f * self.focal_px + r * xx + u * yy).normalize()
    }

    /// The pixel coordinates where direction `d` (robot frame) images, if in front.
    pub fn pixel_of(&self, d: &Vector3<f64>) -> Option<(f64, f64)> {
        let [f, r, u] = self.basis();
        let z = d.dot(&f);
        if z <= 1e-9 {
            return None;
        }
        let xx = self.focal_px * d.dot(&r) / z;
        let yy = self.focal_px * d.dot(&u) / z;
        Some((xx + self.cx_px - 0.5, self.cy_px - yy - 0.5))
    }

    /// The floor point (robot frame, mm) seen at pixel coordinates `(x, y)`, or `None` at and
    /// above the horizon (the floor homography).
    pub fn floor_point(&self, x: f64, y: f64) -> Option<Point2<f64>> {
        let d = self.direction(x, y);
        if d.z >= -1e-6 {
            return None;
        }
        let t = self.height_mm / -d.z;
        Some(Point2::new(
            self.mount_mm[0] + t * d.x,
            self.mount_mm[1] + t * d.y,
        ))
    }

    /// The pixel coordinates of floor point `p` (robot frame, mm), if the camera faces it.
    pub fn project_floor(&self, p: &Point2<f64>) -> Option<(f64, f64)> {
        let d = Vector3::new(
            p.x - self.mount_mm[0],
            p.y - self.mount_mm[1],
            -self.height_mm,
        );
        self.pixel_of(&d)
    }

    /// The pixel coordinates of the direction at `azimuth` (counter-clockwise from the robot's
    /// forward axis) and `elevation` (up from the horizontal), rad.
    pub fn pixel_at(&self, azimuth_rad: f64, elevation_rad: f64) -> Option<(f64, f64)> {
        let (sa, ca) = azimuth_rad.sin_cos();
        let (se, ce) = elevation_rad.sin_cos();
        self.pixel_of(&Vector3::new(ce * ca, ce * sa, se))
    }

    /// Whether pixel coordinates `(x, y)` lie inside the image (with `margin` px to spare).
    pub fn inside(&self, x: f64, y: f64, margin: f64) -> bool {
        x >= margin
            && y >= margin
            && x <= self.width_px as f64 - 1.0 - margin
            && y <= self.height_px as f64 - 1.0 - margin
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing::camera;

    #[test]
    fn the_principal_ray_meets_the_floor_at_height_over_tan_tilt() {
        let c = camera();
        // The principal point lies between pixels 79 and 80 (and 59 and 60).
        let p = c.floor_point(79.5, 59.5).unwrap();
        assert!(
            (p.x - 100.0 / 25f64.to_radians().tan()).abs() < 1e-9,
            "{p:?}"
        );
        assert!(p.y.abs() < 1e-9);
        // Right of the image is the robot's right.
        assert!(c.floor_point(150.0, 100.0).unwrap().y < 0.0);
        // The top row of a 25-degree tilt with a 46.8-degree field is below the horizon.
        assert!(c.floor_point(80.0, 0.0).is_some());
        let mut up = c.clone();
        up.tilt_rad = 0.0;
        assert!(up.floor_point(80.0, 10.0).is_none());
    }

    #[test]
    fn floor_points_project_back_to_their_pixels() {
        let mut c = camera();
        c.mount_mm = [30.0, -5.0];
        for &(x, y) in &[(3.0, 117.0), (80.0, 60.0), (150.5, 20.25), (40.0, 90.0)] {
            let p = c.floor_point(x, y).unwrap();
            let (u, v) = c.project_floor(&p).unwrap();
            assert!(
                (u - x).abs() < 1e-9 && (v - y).abs() < 1e-9,
                "{x},{y} -> {u},{v}"
            );
        }
        let d = c.direction(12.0, 34.0);
        let (az, el) = (d.y.atan2(d.x), d.z.asin());
        let (u, v) = c.pixel_at(az, el).unwrap();
        assert!((u - 12.0).abs() < 1e-9 && (v - 34.0).abs() < 1e-9);
    }
}
