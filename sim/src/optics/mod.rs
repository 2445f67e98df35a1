//! Camera and mirror optics: for every pixel, the ray that leaves the sensor into the scene.
//!
//! Sensors look up at a mirror on the robot's vertical axis (hyperbolic, conical, spherical) or
//! out into the room (pinhole). Image coordinates: pixel `(u, v)` has its centre at
//! `X = u + 0.5 - c_x`, `Y = c_y - (v + 0.5)`; for the mirrors the camera ray is
//! `(X, Y, f)` in the robot frame (x forward, y left, z up), so a floor point at azimuth `phi`
//! images at image angle `Phi = phi` (eq. (2) of the corner paper) and `R = sqrt(X^2 + Y^2)`.
//!
//! Each mirror is an analytic ray-surface intersection with its normal; the reflected ray is
//! `r = d - 2 (d . n) n`. Rays that miss the mirror give `None` (black pixels). The same math
//! runs in the WGSL tracer (`render/trace.wgsl`).

pub mod calibrated;
pub mod conical;
pub mod hyperbolic;
pub mod mounting;
pub mod pinhole;
pub mod ray;
pub mod spherical;

pub use calibrated::CalibratedCamera;
pub use conical::ConicalMirror;
pub use hyperbolic::HyperbolicMirror;
pub use mounting::{MirrorFrame, MirrorMounting};
use omniloop_problem::{Problem, Problems};
pub use pinhole::PinholeCamera;
pub use ray::{Ray, reflect, solve_quadratic};
pub use spherical::SphericalMirror;

/// The optics of one sensor.
#[derive(Debug, Clone, PartialEq)]
pub enum Optics {
    /// Single-viewpoint hyperboloidal mirror.
    Hyperbolic(HyperbolicMirror),
    /// Conical mirror (non-central).
    Conical(ConicalMirror),
    /// Spherical / hemispherical mirror (non-central).
    Spherical(SphericalMirror),
    /// Plain pinhole camera with pan and tilt.
    Pinhole(PinholeCamera),
    /// A camera known by its calibration file (a standard camera model and its pose).
    Calibrated(CalibratedCamera),
}

impl Optics {
    /// The ray into the scene for image coordinates `(X, Y)` (pixels from the principal point,
    /// Y up), in the sensor frame: origin on the floor below the sensor's axis, z up.
    pub fn scene_ray(&self, x_px: f64, y_px: f64) -> Option<Ray> {
        match self {
            Optics::Hyperbolic(m) => m.scene_ray(x_px, y_px),
            Optics::Conical(m) => m.scene_ray(x_px, y_px),
            Optics::Spherical(m) => m.scene_ray(x_px, y_px),
            Optics::Pinhole(c) => c.scene_ray(x_px, y_px),
            Optics::Calibrated(c) => c.scene_ray(x_px, y_px),
        }
    }

    /// The largest horizontal distance of a scene ray's origin from the sensor axis (the
    /// mirror's rim radius; 0 for a pinhole camera).
    pub fn max_origin_offset_mm(&self) -> f64 {
        match self {
            Optics::Hyperbolic(m) => m.rim_radius_mm,
            Optics::Conical(m) => m.radius_mm,
            Optics::Spherical(m) => m.radius_mm,
            Optics::Pinhole(_) => 0.0,
            Optics::Calibrated(c) => c.max_origin_offset_mm(),
        }
    }

    /// Its numbers that break a rule, each naming its field under the sensor
    /// (`hyperbolic.c_mm`), each mirror checking its own.
    pub fn problems(&self) -> Vec<Problem> {
        let list = match self {
            Optics::Hyperbolic(m) => m.problems(),
            Optics::Conical(m) => m.problems(),
            Optics::Spherical(m) => m.problems(),
            Optics::Pinhole(c) => c.problems(),
            Optics::Calibrated(c) => c.problems(),
        };
        let mut p = Problems::under(self.kind());
        p.extend(list);
        p.into_vec()
    }

    /// The pinhole camera, when the optics are one.
    pub fn pinhole(&self) -> Option<&PinholeCamera> {
        match self {
            Optics::Pinhole(c) => Some(c),
            _ => None,
        }
    }

    /// The conical mirror, when the optics are one.
    pub fn conical(&self) -> Option<&ConicalMirror> {
        match self {
            Optics::Conical(m) => Some(m),
            _ => None,
        }
    }

    /// The frame of its mirror, for tracing it off its place (`None` for a camera without a
    /// mirror).
    pub fn mirror_frame(&self) -> Option<MirrorFrame> {
        Some(match self {
            Optics::Hyperbolic(m) => {
                let c = m.focal_half_distance_mm();
                let z0 = m.focus_height_mm - c;
                MirrorFrame {
                    surface: mounting::Surface::Hyperboloid {
                        a: m.a_mm,
                        b: m.b_mm,
                        rim: m.rim_radius_mm,
                    },
                    z0_mm: z0,
                    pinhole_mm: z0 - c,
                    pivot_mm: z0 + m.b_mm,
                    focal_px: m.focal_px,
                }
            }
            Optics::Conical(m) => MirrorFrame {
                surface: mounting::Surface::Cone {
                    k: (m.apex_angle_deg.to_radians() / 2.0).tan(),
                    tip: m.tip_distance_mm,
                    radius: m.radius_mm,
                },
                z0_mm: m.lens_height_mm,
                pinhole_mm: m.lens_height_mm,
                pivot_mm: m.lens_height_mm + m.tip_distance_mm,
                focal_px: m.focal_px,
            },
            Optics::Spherical(m) => MirrorFrame {
                surface: mounting::Surface::Sphere {
                    centre: m.camera_distance_mm,
                    r: m.radius_mm,
                },
                z0_mm: m.lens_height_mm,
                pinhole_mm: m.lens_height_mm,
                pivot_mm: m.lens_height_mm + m.camera_distance_mm - m.radius_mm,
                focal_px: m.focal_px,
            },
            Optics::Pinhole(_) | Optics::Calibrated(_) => return None,
        })
    }

    /// The calibrated camera, when the optics are one.
    pub fn calibrated(&self) -> Option<&CalibratedCamera> {
        match self {
            Optics::Calibrated(c) => Some(c),
            _ => None,
        }
    }

    /// Short name of the kind of optics: the name of its table in a scenario.
    pub fn kind(&self) -> &'static str {
        match self {
            Optics::Hyperbolic(_) => "hyperbolic",
            Optics::Conical(_) => "conical",
            Optics::Spherical(_) => "spherical",
            Optics::Pinhole(_) => "pinhole",
            Optics::Calibrated(_) => "calibrated",
        }
    }
}
