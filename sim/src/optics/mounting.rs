//! A mirror that does not sit where it should (`[robot.sensors.mounting]`): tilted against the
//! camera's axis and shifted from its nominal place, traced exactly.
//!
//! The camera stays where it is; the mirror is its nominal surface moved by
//! `s -> R (s - P) + P + o` (sensor frame: origin on the floor below the axis, z up), with `P`
//! the pivot, the mirror's vertex on the axis (the point of its surface nearest the camera), `R`
//! the tilt by `mirror_tilt_deg` of the mirror's axis toward the azimuth `tilt_azimuth_deg`
//! (from the robot's forward axis, counter-clockwise), and `o = mirror_offset_mm`. A pixel's ray
//! is traced in the nominal mirror's frame, where the camera sits at `R^T (C - P - o) + P` and
//! looks along `R^T d`, and the reflected ray is moved back by the same map: the same
//! intersection as the nominal mirror's, from an origin off its axis. A single-viewpoint mirror
//! so moved has no single viewpoint any more.

use super::ray::{Ray, reflect, solve_quadratic};
use nalgebra::{Point3, Rotation3, Unit, Vector3};
use omniloop_problem::{Problem, Problems};
use serde::{Deserialize, Serialize};

/// How the mirror is off its nominal place; the default is where it should be.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MirrorMounting {
    /// Tilt of the mirror's axis against the camera's, degrees.
    pub mirror_tilt_deg: f64,
    /// The direction the axis tilts toward, degrees from the robot's forward axis.
    pub tilt_azimuth_deg: f64,
    /// The mirror's shift from its nominal place `[x, y, z]`, mm (sensor frame).
    pub mirror_offset_mm: [f64; 3],
    /// Whether the robot calibrated itself on the mirror as it is (its image-to-floor map then
    /// traced with the error); by default it keeps the nominal calibration.
    pub self_calibrated: bool,
}

impl MirrorMounting {
    /// Whether the mirror sits where it should.
    pub fn is_nominal(&self) -> bool {
        self.mirror_tilt_deg == 0.0 && self.mirror_offset_mm == [0.0; 3]
    }

    /// The tilt `R`.
    pub fn rotation(&self) -> Rotation3<f64> {
        let a = self.tilt_azimuth_deg.to_radians();
        let axis = Unit::new_normalize(Vector3::new(-a.sin(), a.cos(), 0.0));
        Rotation3::from_axis_angle(&axis, self.mirror_tilt_deg.to_radians())
    }

    /// Its values that break a rule, each naming its key.
    pub fn problems(&self) -> Vec<Problem> {
        let mut p = Problems::new();
        if !(self.mirror_tilt_deg.is_finite() && (0.0..=30.0).contains(&self.mirror_tilt_deg)) {
            p.fail(
                "mirror_tilt_deg",
                format!("must lie in [0, 30] (got {})", self.mirror_tilt_deg),
            );
        }
        if !self.tilt_azimuth_deg.is_finite() {
            p.fail("tilt_azimuth_deg", "must be a finite number");
        }
        if self
            .mirror_offset_mm
            .iter()
            .any(|v| !v.is_finite() || v.abs() > 100.0)
        {
            p.fail("mirror_offset_mm", "must be three numbers within 100 mm");
        }
        p.into_vec()
    }
}

/// A mirror's surface in its own frame (`L`, whose origin is `z0_mm` above the floor on the
/// axis), and where its camera and pivot are.
#[derive(Debug, Clone, Copy)]
pub struct MirrorFrame {
    /// The surface.
    pub surface: Surface,
    /// Height of `L`'s origin above the floor.
    pub z0_mm: f64,
    /// Height of the camera's pinhole above the floor.
    pub pinhole_mm: f64,
    /// Height of the pivot (the mirror's vertex) above the floor.
    pub pivot_mm: f64,
    /// The camera's focal length, px.
    pub focal_px: f64,
}

/// The three mirrors' surfaces, in their frames `L`.
#[derive(Debug, Clone, Copy)]
pub enum Surface {
    /// `Z^2 / b^2 - rho^2 / a^2 = 1`, the upper sheet, `rho <= rim`.
    Hyperboloid {
        /// a.
        a: f64,
        /// b.
        b: f64,
        /// Rim radius.
        rim: f64,
    },
    /// `rho = k (z - tip)`, `z >= tip`, `rho <= radius`.
    Cone {
        /// tan of the half apex angle.
        k: f64,
        /// Tip height in `L`.
        tip: f64,
        /// Rim radius.
        radius: f64,
    },
    /// `|p - (0, 0, centre)| = r`, the near side.
    Sphere {
        /// Centre height in `L`.
        centre: f64,
        /// Radius.
        r: f64,
    },
}

impl MirrorFrame {
    /// The scene ray of image coordinates `(X, Y)` with the mirror mounted as `m` (sensor
    /// frame), or `None` where the camera sees no mirror.
    pub fn scene_ray(&self, m: &MirrorMounting, x_px: f64, y_px: f64) -> Option<Ray> {
        let r = m.rotation();
        let pivot = Vector3::new(0.0, 0.0, self.pivot_mm);
        let offset = Vector3::from(m.mirror_offset_mm);
        let d = Vector3::new(x_px, y_px, self.focal_px).normalize();
        let camera = Vector3::new(0.0, 0.0, self.pinhole_mm);
        // Into the nominal mirror's frame L.
        let o =
            r.inverse() * (camera - pivot - offset) + pivot - Vector3::new(0.0, 0.0, self.z0_mm);
        let dl = r.inverse() * d;
        let (p, n) = self.surface.hit(&o, &dl)?;
        let reflected = reflect(dl, n);
        let s = p.coords + Vector3::new(0.0, 0.0, self.z0_mm);
        Some(Ray {
            origin: Point3::from(r * (s - pivot) + pivot + offset),
            dir: r * reflected,
            path_mm: (p.coords - o).norm(),
        })
    }
}

impl Surface {
    /// The first point where the ray from `o` along unit `d` meets the surface (frame `L`),
    /// with the surface's unit normal there, facing the ray.
    pub fn hit(&self, o: &Vector3<f64>, d: &Vector3<f64>) -> Option<(Point3<f64>, Vector3<f64>)> {
        match *self {
            Surface::Hyperboloid { a, b, rim } => {
                let (a2, b2) = (a * a, b * b);
                let qa = d.z * d.z / b2 - (d.x * d.x + d.y * d.y) / a2;
                let qb = 2.0 * (o.z * d.z / b2 - (o.x * d.x + o.y * d.y) / a2);
                let qc = o.z * o.z / b2 - (o.x * o.x + o.y * o.y) / a2 - 1.0;
                let (t0, t1) = solve_quadratic(qa, qb, qc)?;
                let t = [t0, t1]
                    .into_iter()
                    .find(|&t| t > 0.0 && o.z + t * d.z > 0.0)?;
                let p = o + d * t;
                if p.x * p.x + p.y * p.y > rim * rim {
                    return None;
                }
                let n = Vector3::new(p.x / a2, p.y / a2, -p.z / b2).normalize();
                Some((Point3::from(p), n))
            }
            Surface::Cone { k, tip, radius } => {
                let k2 = k * k;
                let h = o.z - tip;
                let qa = d.x * d.x + d.y * d.y - k2 * d.z * d.z;
                let qb = 2.0 * (o.x * d.x + o.y * d.y) - 2.0 * k2 * h * d.z;
                let qc = o.x * o.x + o.y * o.y - k2 * h * h;
                let (t0, t1) = solve_quadratic(qa, qb, qc)?;
                let t = [t0, t1]
                    .into_iter()
                    .find(|&t| t > 0.0 && o.z + t * d.z - tip >= 0.0)?;
                let p = o + d * t;
                let rho = p.x.hypot(p.y);
                if rho > radius || rho < 1e-12 {
                    return None;
                }
                let n = Vector3::new(p.x / rho, p.y / rho, -k).normalize();
                Some((Point3::from(p), n))
            }
            Surface::Sphere { centre, r } => {
                let c = Vector3::new(0.0, 0.0, centre);
                let oc = o - c;
                let (t0, _) = solve_quadratic(1.0, 2.0 * d.dot(&oc), oc.norm_squared() - r * r)?;
                if t0 <= 0.0 {
                    return None;
                }
                let p = o + d * t0;
                Some((Point3::from(p), (p - c) / r))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::{ConicalMirror, HyperbolicMirror, Optics, SphericalMirror};

    fn mirrors() -> Vec<Optics> {
        vec![
            Optics::Hyperbolic(HyperbolicMirror::corner_paper()),
            Optics::Conical(ConicalMirror {
                apex_angle_deg: 90.0,
                radius_mm: 30.0,
                tip_distance_mm: 100.0,
                focal_px: 520.0,
                lens_height_mm: 100.0,
            }),
            Optics::Spherical(SphericalMirror {
                radius_mm: 30.0,
                camera_distance_mm: 150.0,
                focal_px: 530.0,
                lens_height_mm: 150.0,
            }),
        ]
    }

    #[test]
    fn a_nominal_mounting_traces_the_mirrors_own_rays() {
        let m = MirrorMounting::default();
        for optics in mirrors() {
            let frame = optics.mirror_frame().unwrap();
            let mut n = 0;
            for (x, y) in [
                (0.5, 0.5),
                (30.5, -12.5),
                (-60.5, 44.5),
                (90.5, 10.5),
                (2.5, -110.5),
            ] {
                let a = optics.scene_ray(x, y);
                let b = frame.scene_ray(&m, x, y);
                match (a, b) {
                    (Some(a), Some(b)) => {
                        assert!(
                            (a.origin - b.origin).norm() < 1e-9,
                            "{}: {a:?} {b:?}",
                            optics.kind()
                        );
                        assert!(
                            (a.dir - b.dir).norm() < 1e-9,
                            "{}: {a:?} {b:?}",
                            optics.kind()
                        );
                        n += 1;
                    }
                    (None, None) => {}
                    other => panic!("{}: {other:?}", optics.kind()),
                }
            }
            assert!(n >= 3, "{}", optics.kind());
        }
    }

    #[test]
    fn a_mirror_shifted_with_the_camera_moves_every_ray_with_it() {
        // Raising the mirror by 5 mm with the camera kept is, for the rays, the same as
        // lowering the camera by 5 mm: a pure vertical shift of the mirror moves the reflected
        // ray's origin up by 5 mm relative to the ray of a camera 5 mm lower.
        let optics = Optics::Hyperbolic(HyperbolicMirror::corner_paper());
        let frame = optics.mirror_frame().unwrap();
        let up = MirrorMounting {
            mirror_offset_mm: [0.0, 0.0, 5.0],
            ..MirrorMounting::default()
        };
        let lowered = MirrorFrame {
            pinhole_mm: frame.pinhole_mm - 5.0,
            ..frame
        };
        for (x, y) in [(10.5, 3.5), (-50.5, 20.5), (70.5, -70.5)] {
            let a = frame.scene_ray(&up, x, y).unwrap();
            let b = lowered.scene_ray(&MirrorMounting::default(), x, y).unwrap();
            assert!((a.origin - b.origin - Vector3::new(0.0, 0.0, 5.0)).norm() < 1e-9);
            assert!((a.dir - b.dir).norm() < 1e-12);
        }
    }
}
