//! Sensors mounted on a robot: image size, principal point, noise and optics.

use crate::optics::{
    CalibratedCamera, ConicalMirror, HyperbolicMirror, MirrorMounting, Optics, PinholeCamera,
    SphericalMirror,
};
use crate::render::effects::CameraEffects;
use serde::{Deserialize, Serialize};

/// A sensor as written in a scenario (`[[robot.sensors]]`), with its optics as one typed value:
/// in the file, exactly one of the tables `hyperbolic`, `conical`, `spherical`, `pinhole`,
/// `calibrated`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawSensorSpec", into = "RawSensorSpec")]
pub struct SensorSpec {
    /// Name the sensor is referred to by (`--sensor NAME`).
    pub name: String,
    /// Image width.
    pub width_px: u32,
    /// Image height.
    pub height_px: u32,
    /// Principal point (default: the image centre; a calibrated camera's: its model's).
    pub principal_point_px: Option<[f64; 2]>,
    /// Standard deviation of the Gaussian noise added to each channel of each pixel, in levels
    /// of 255.
    pub noise_sigma: f64,
    /// Grey levels the camera delivers (e.g. 16 for the resection paper's digitizer): the image
    /// becomes grey, its luminance quantised to this many levels spread over 0..255, after the
    /// noise. Default: colour, 256 levels a channel.
    pub grey_levels: Option<u32>,
    /// Position of the sensor's axis on the robot (x forward, y left).
    pub mount_mm: [f64; 2],
    /// Its optics: a mirror under which the camera looks up, or a pinhole camera.
    pub optics: Optics,
    /// What the real camera does to the image (`[robot.sensors.effects]`; default: nothing).
    pub effects: CameraEffects,
    /// How the mirror is off its nominal place (`[robot.sensors.mounting]`; default: on it).
    pub mounting: MirrorMounting,
}

/// A sensor as the file writes it: the optics as four optional tables, of which exactly one
/// must be given; turned into a [`SensorSpec`] once, when the scenario is parsed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSensorSpec {
    name: String,
    #[serde(default = "default_width")]
    width_px: u32,
    #[serde(default = "default_height")]
    height_px: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    principal_point_px: Option<[f64; 2]>,
    #[serde(default = "default_noise")]
    noise_sigma: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    grey_levels: Option<u32>,
    #[serde(default)]
    mount_mm: [f64; 2],
    #[serde(default, skip_serializing_if = "CameraEffects::is_off")]
    effects: CameraEffects,
    #[serde(default, skip_serializing_if = "MirrorMounting::is_nominal")]
    mounting: MirrorMounting,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    hyperbolic: Option<HyperbolicMirror>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    conical: Option<ConicalMirror>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    spherical: Option<SphericalMirror>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pinhole: Option<PinholeCamera>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    calibrated: Option<CalibratedCamera>,
}

/// A sensor written without exactly one optics table.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "sensor {sensor:?}: a sensor needs exactly one of the tables hyperbolic, conical, spherical, \
     pinhole, calibrated (found {})",
    found(.given)
)]
pub struct OpticsCountError {
    /// The sensor's name.
    pub sensor: String,
    /// The optics tables it has.
    pub given: Vec<&'static str>,
}

/// `none`, or the tables given.
fn found(given: &[&str]) -> String {
    if given.is_empty() {
        "none".to_string()
    } else {
        given.join(", ")
    }
}

impl TryFrom<RawSensorSpec> for SensorSpec {
    type Error = OpticsCountError;

    fn try_from(r: RawSensorSpec) -> Result<Self, OpticsCountError> {
        let mut given: Vec<Optics> = Vec::new();
        given.extend(r.hyperbolic.map(Optics::Hyperbolic));
        given.extend(r.conical.map(Optics::Conical));
        given.extend(r.spherical.map(Optics::Spherical));
        given.extend(r.pinhole.map(Optics::Pinhole));
        given.extend(r.calibrated.map(Optics::Calibrated));
        let optics = match given.len() {
            1 => given.remove(0),
            _ => {
                return Err(OpticsCountError {
                    sensor: r.name,
                    given: given.iter().map(Optics::kind).collect(),
                });
            }
        };
        Ok(Self {
            name: r.name,
            width_px: r.width_px,
            height_px: r.height_px,
            principal_point_px: r.principal_point_px,
            noise_sigma: r.noise_sigma,
            grey_levels: r.grey_levels,
            mount_mm: r.mount_mm,
            optics,
            effects: r.effects,
            mounting: r.mounting,
        })
    }
}

impl From<SensorSpec> for RawSensorSpec {
    fn from(s: SensorSpec) -> Self {
        let mut r = Self {
            name: s.name,
            width_px: s.width_px,
            height_px: s.height_px,
            principal_point_px: s.principal_point_px,
            noise_sigma: s.noise_sigma,
            grey_levels: s.grey_levels,
            mount_mm: s.mount_mm,
            effects: s.effects,
            mounting: s.mounting,
            hyperbolic: None,
            conical: None,
            spherical: None,
            pinhole: None,
            calibrated: None,
        };
        match s.optics {
            Optics::Hyperbolic(m) => r.hyperbolic = Some(m),
            Optics::Conical(m) => r.conical = Some(m),
            Optics::Spherical(m) => r.spherical = Some(m),
            Optics::Pinhole(c) => r.pinhole = Some(c),
            Optics::Calibrated(c) => r.calibrated = Some(c),
        }
        r
    }
}

fn default_width() -> u32 {
    256
}
fn default_height() -> u32 {
    220
}
fn default_noise() -> f64 {
    4.0
}

impl SensorSpec {
    /// The reconstructed corner-paper camera: hyperbolic mirror, 256 x 220, noise 4 levels.
    pub fn corner_paper(name: &str) -> Self {
        Self {
            name: name.to_string(),
            width_px: 256,
            height_px: 220,
            principal_point_px: None,
            noise_sigma: 4.0,
            grey_levels: None,
            mount_mm: [0.0, 0.0],
            optics: Optics::Hyperbolic(HyperbolicMirror::corner_paper()),
            effects: CameraEffects::default(),
            mounting: MirrorMounting::default(),
        }
    }

    /// Resolves the description into a sensor.
    pub fn build(&self) -> Sensor {
        let [cx, cy] = self
            .principal_point_px
            .or_else(|| self.optics.calibrated()?.principal_point_px())
            .unwrap_or([self.width_px as f64 / 2.0, self.height_px as f64 / 2.0]);
        Sensor {
            name: self.name.clone(),
            width_px: self.width_px,
            height_px: self.height_px,
            cx_px: cx,
            cy_px: cy,
            noise_sigma: self.noise_sigma,
            grey_levels: self.grey_levels,
            mount_mm: self.mount_mm,
            optics: self.optics.clone(),
            effects: self.effects.clone(),
            mounting: self.mounting.clone(),
        }
    }
}

/// A sensor ready to render.
#[derive(Debug, Clone, PartialEq)]
pub struct Sensor {
    /// Name.
    pub name: String,
    /// Image width.
    pub width_px: u32,
    /// Image height.
    pub height_px: u32,
    /// Principal point, x (pixels from the left edge).
    pub cx_px: f64,
    /// Principal point, y (pixels from the top edge).
    pub cy_px: f64,
    /// Noise sigma in levels.
    pub noise_sigma: f64,
    /// Grey levels, when the camera is a quantised grey one.
    pub grey_levels: Option<u32>,
    /// Axis position on the robot.
    pub mount_mm: [f64; 2],
    /// Optics.
    pub optics: Optics,
    /// Camera effects applied to each traced frame.
    pub effects: CameraEffects,
    /// How the mirror is off its nominal place.
    pub mounting: MirrorMounting,
}

impl Sensor {
    /// The scene ray of image coordinates `(X, Y)` in the sensor frame, the mirror as it is
    /// mounted.
    pub fn scene_ray(&self, x_px: f64, y_px: f64) -> Option<crate::optics::Ray> {
        match self
            .optics
            .mirror_frame()
            .filter(|_| !self.mounting.is_nominal())
        {
            Some(frame) => frame.scene_ray(&self.mounting, x_px, y_px),
            None => self.optics.scene_ray(x_px, y_px),
        }
    }

    /// The scene ray the robot's calibration is traced with: the nominal mirror's, unless the
    /// robot calibrated itself on the mirror as it is mounted.
    pub fn calibration_ray(&self, x_px: f64, y_px: f64) -> Option<crate::optics::Ray> {
        if self.mounting.self_calibrated {
            self.scene_ray(x_px, y_px)
        } else {
            self.optics.scene_ray(x_px, y_px)
        }
    }

    /// Image coordinates `(X, Y)` (from the principal point, Y up) of pixel `(u, v)`'s centre.
    pub fn image_coords(&self, u: u32, v: u32) -> (f64, f64) {
        (u as f64 + 0.5 - self.cx_px, self.cy_px - (v as f64 + 0.5))
    }

    /// The scene ray of pixel `(u, v)` in the robot frame, or `None` where the camera sees no
    /// mirror.
    pub fn pixel_ray(&self, u: u32, v: u32) -> Option<crate::optics::Ray> {
        let (x, y) = self.image_coords(u, v);
        self.scene_ray(x, y).map(|ray| self.mounted(ray))
    }

    /// Calls `f` with every pixel's [`Self::pixel_ray`], row by row from the top: the same rays
    /// to the bit, with what a pinhole camera's pixels share (its basis, two sines and cosines)
    /// worked out once, not once a pixel (a camera on a pan unit is traced again at every
    /// frame). Plain loops rather than an iterator of rows, so that the per-pixel work is
    /// inlined into the caller's loop whatever the compiler's budget.
    pub fn for_each_pixel_ray(&self, mut f: impl FnMut(Option<crate::optics::Ray>)) {
        let pinhole = match &self.optics {
            Optics::Pinhole(c) => Some((c, c.basis())),
            _ => None,
        };
        for v in 0..self.height_px {
            for u in 0..self.width_px {
                f(match &pinhole {
                    Some((c, basis)) => {
                        let (x, y) = self.image_coords(u, v);
                        Some(self.mounted(c.ray_in(basis, x, y)))
                    }
                    None => self.pixel_ray(u, v),
                });
            }
        }
    }

    /// `ray` from the sensor's frame to the robot's: moved by the sensor's place on the robot.
    fn mounted(&self, mut ray: crate::optics::Ray) -> crate::optics::Ray {
        ray.origin.x += self.mount_mm[0];
        ray.origin.y += self.mount_mm[1];
        ray
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every ray's numbers as bits, `None` for a pixel that sees no mirror.
    fn bits(rays: impl Iterator<Item = Option<crate::optics::Ray>>) -> Vec<Option<[u64; 7]>> {
        rays.map(|r| {
            r.map(|r| {
                let (o, d) = (r.origin, r.dir);
                [o.x, o.y, o.z, d.x, d.y, d.z, r.path_mm].map(f64::to_bits)
            })
        })
        .collect()
    }

    #[test]
    fn all_pixel_rays_at_once_are_each_pixels_ray_to_the_bit() {
        let mut mirror = SensorSpec::corner_paper("omni");
        (mirror.width_px, mirror.height_px, mirror.mount_mm) = (40, 30, [12.5, -7.0]);
        let mut panned = mirror.clone();
        panned.optics = Optics::Pinhole(PinholeCamera {
            focal_px: 51.6,
            height_mm: 280.0,
            pan_deg: -37.3,
            tilt_deg: -11.0,
            pan_rate_limit_deg_s: 60.0,
        });
        for spec in [mirror, panned] {
            let s = spec.build();
            let one_by_one = (0..s.height_px)
                .flat_map(|v| (0..s.width_px).map(move |u| (u, v)))
                .map(|(u, v)| s.pixel_ray(u, v));
            let mut each = Vec::new();
            s.for_each_pixel_ray(|r| each.push(r));
            let all = bits(each.into_iter());
            assert_eq!(all.len(), 40 * 30);
            // The mirror's corners see no mirror; the pinhole camera sees everywhere.
            assert!(all.iter().any(Option::is_some), "{}", s.name);
            assert_eq!(all, bits(one_by_one), "{:?}", s.optics.kind());
        }
    }
}
