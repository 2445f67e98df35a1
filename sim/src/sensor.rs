//! Sensors mounted on a robot: image size, principal point, noise and optics.

use crate::SimError;
use crate::optics::{ConicalMirror, HyperbolicMirror, Optics, PinholeCamera, SphericalMirror};
use serde::{Deserialize, Serialize};

/// A sensor as written in a scenario (`[[robot.sensors]]`): exactly one of the optics tables
/// `hyperbolic`, `conical`, `spherical`, `pinhole` is given.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorSpec {
    /// Name the sensor is referred to by (`--sensor NAME`).
    pub name: String,
    /// Image width.
    #[serde(default = "default_width")]
    pub width_px: u32,
    /// Image height.
    #[serde(default = "default_height")]
    pub height_px: u32,
    /// Principal point (default: the image centre).
    #[serde(default)]
    pub principal_point_px: Option<[f64; 2]>,
    /// Standard deviation of the Gaussian noise added to each channel of each pixel, in levels
    /// of 255.
    #[serde(default = "default_noise")]
    pub noise_sigma: f64,
    /// Grey levels the camera delivers (e.g. 16 for the resection paper's digitizer): the image
    /// becomes grey, its luminance quantised to this many levels spread over 0..255, after the
    /// noise. Default: colour, 256 levels a channel.
    #[serde(default)]
    pub grey_levels: Option<u32>,
    /// Position of the sensor's axis on the robot (x forward, y left).
    #[serde(default)]
    pub mount_mm: [f64; 2],
    /// Single-viewpoint hyperboloidal mirror.
    #[serde(default)]
    pub hyperbolic: Option<HyperbolicMirror>,
    /// Conical mirror.
    #[serde(default)]
    pub conical: Option<ConicalMirror>,
    /// Spherical (hemispherical) mirror.
    #[serde(default)]
    pub spherical: Option<SphericalMirror>,
    /// Pinhole camera.
    #[serde(default)]
    pub pinhole: Option<PinholeCamera>,
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
            hyperbolic: Some(HyperbolicMirror::corner_paper()),
            conical: None,
            spherical: None,
            pinhole: None,
        }
    }

    /// The names of the optics tables present.
    pub fn optics_present(&self) -> Vec<&'static str> {
        let mut v = Vec::new();
        if self.hyperbolic.is_some() {
            v.push("hyperbolic");
        }
        if self.conical.is_some() {
            v.push("conical");
        }
        if self.spherical.is_some() {
            v.push("spherical");
        }
        if self.pinhole.is_some() {
            v.push("pinhole");
        }
        v
    }

    /// Resolves the description into a sensor.
    pub fn build(&self) -> Result<Sensor, SimError> {
        let present = self.optics_present();
        if present.len() != 1 {
            return Err(SimError::Invalid(format!(
                "sensor {:?} needs exactly one of hyperbolic, conical, spherical, pinhole \
                 (found {})",
                self.name,
                if present.is_empty() {
                    "none".to_string()
                } else {
                    present.join(", ")
                }
            )));
        }
        let optics = if let Some(m) = &self.hyperbolic {
            Optics::Hyperbolic(m.clone())
        } else if let Some(m) = &self.conical {
            Optics::Conical(m.clone())
        } else if let Some(m) = &self.spherical {
            Optics::Spherical(m.clone())
        } else if let Some(c) = &self.pinhole {
            Optics::Pinhole(c.clone())
        } else {
            unreachable!("one optics table is present")
        };
        let [cx, cy] = self
            .principal_point_px
            .unwrap_or([self.width_px as f64 / 2.0, self.height_px as f64 / 2.0]);
        Ok(Sensor {
            name: self.name.clone(),
            width_px: self.width_px,
            height_px: self.height_px,
            cx_px: cx,
            cy_px: cy,
            noise_sigma: self.noise_sigma,
            grey_levels: self.grey_levels,
            mount_mm: self.mount_mm,
            optics,
        })
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
}

impl Sensor {
    /// Image coordinates `(X, Y)` (from the principal point, Y up) of pixel `(u, v)`'s centre.
    pub fn image_coords(&self, u: u32, v: u32) -> (f64, f64) {
        (u as f64 + 0.5 - self.cx_px, self.cy_px - (v as f64 + 0.5))
    }

    /// The scene ray of pixel `(u, v)` in the robot frame, or `None` where the camera sees no
    /// mirror.
    pub fn pixel_ray(&self, u: u32, v: u32) -> Option<crate::optics::Ray> {
        let (x, y) = self.image_coords(u, v);
        let mut ray = self.optics.scene_ray(x, y)?;
        ray.origin.x += self.mount_mm[0];
        ray.origin.y += self.mount_mm[1];
        Some(ray)
    }
}
