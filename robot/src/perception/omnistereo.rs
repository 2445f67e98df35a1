//! Conical omnistereo (Spacek and Burbridge): ranges to the map's coloured landmarks,
//! trilateration, the visual compass and the interframe motion, from the two cameras under the
//! coaxial cones.
//!
//! On its first frames the stage measures each mirror's rim in the image (its centre and
//! `r_m`) and calibrates `v` by eq. (2), as the paper does; it never reads the cameras' focal
//! length from a specification. Then every cycle: the landmarks found in both images by their
//! colours are ranged by eq. (1); their ranges (to the near face, plus the landmark's radius:
//! to its centre) and bearings give a pose fix by trilateration; the compass reads the turn
//! since the previous frame and, with the landmarks seen in both frames, the clustering gives
//! the translation. The motion is recorded, not fused: a 15 mm step measured to a few
//! millimetres is no better than the wheels over 50 ms.

use super::stage::{
    Belief, CameraNeed, Perceived, Sighting, Stage, StageEntry, WorldNeed, image, vision_settings,
};
use crate::RobotError;
use crate::boundary::Observation;
use crate::config::{MapLandmark, StereoRig};
use crate::estimates::{Measurement, NotFound};
use crate::percept::Percept;
use image::RgbaImage;
use nalgebra::{Isometry2, Vector2};
use omniloop_problem::Problem;
use omniloop_vision::VisionError;
use omniloop_vision::omnistereo::{
    AngularProfile, FeaturePair, LandmarkRange, MirrorRim, OmnistereoConfig, RangedMark,
    StereoGeometry, densest_cluster, detect_marks, range_marks, translation_candidates,
    trilaterate_with_error,
};

/// The stage's name, in the estimates record and the registry.
pub const NAME: &str = "omnistereo";

/// The `control.pose_source` under which its fixes correct the estimate.
pub const POSE_SOURCE: &str = "omnistereo";

/// The registry's entry.
pub const ENTRY: StageEntry = StageEntry {
    name: NAME,
    summary: "conical omnistereo: ranges by eq. (1), trilateration, visual compass, interframe \
              motion (Spacek and Burbridge, Sect. 2)",
    pose_source: Some(POSE_SOURCE),
    table: None,
    vision_table: Some("omnistereo"),
    check_vision: |v| {
        v.tables
            .check::<OmnistereoConfig>("vision", "omnistereo", |t, p| {
                if let Err(e) = t.validate() {
                    p.fail("", e.to_string());
                }
            })
    },
    asked: |c| c.control.pose_source == POSE_SOURCE,
    camera: CameraNeed::None,
    world: &[WorldNeed::StereoRig],
    check: |c| {
        let mut p = Vec::new();
        if c.map.landmarks.is_empty() {
            let why = "omnistereo trilateration needs landmarks: add [[world.pillars]] of \
                       distinct colours";
            p.push(Problem::new("control.pose_source", why));
        }
        p
    },
    build: |c| {
        let rig = c.stereo.ok_or_else(|| {
            RobotError::Field(Problem::new(
                "control.pose_source",
                "\"omnistereo\" needs the robot's two cones",
            ))
        })?;
        let config = vision_settings(c, "omnistereo")?;
        Ok(Box::new(OmnistereoStage::new(
            config,
            rig,
            &c.map.landmarks,
        )?))
    },
};

/// A landmark of the map the robot identified and measured this cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LandmarkSighting {
    /// Its index in the map.
    pub landmark: usize,
    /// Range from the camera axis to its near face, mm.
    pub range_mm: f64,
    /// Bearing (robot frame), rad.
    pub bearing_rad: f64,
}

/// The robot's motion since the previous frame as its vision read it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionReading {
    /// The rotation the visual compass read, counter-clockwise positive, rad.
    pub rotation_rad: f64,
    /// The translation, in the previous frame's axes, mm; `None` when no feature was seen in
    /// both frames.
    pub translation_mm: Option<Vector2<f64>>,
    /// Features seen in both frames.
    pub features: usize,
    /// Of which the clustering kept.
    pub inliers: usize,
}

/// The landmarks of the map identified and ranged in one cycle.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Landmarks(pub Vec<LandmarkSighting>);

impl Percept for Landmarks {
    /// `landmarks`: each one's index, range and bearing (none: not recorded).
    fn record(&self) -> Option<(&'static str, serde_json::Value)> {
        let each = |l: &LandmarkSighting| {
            serde_json::json!({
                "landmark": l.landmark,
                "range_mm": l.range_mm,
                "bearing_rad": l.bearing_rad,
            })
        };
        (!self.0.is_empty()).then(|| ("landmarks", self.0.iter().map(each).collect()))
    }
}

impl Percept for MotionReading {
    /// `motion`: the compass's turn, the translation, and the features behind it.
    fn record(&self) -> Option<(&'static str, serde_json::Value)> {
        let value = serde_json::json!({
            "rotation_rad": self.rotation_rad,
            "translation_mm": self.translation_mm.map(|t| [t.x, t.y]),
            "features": self.features,
            "inliers": self.inliers,
        });
        Some(("motion", value))
    }
}

/// What the stage measured of its own cameras.
#[derive(Debug, Clone, Copy)]
struct Calibration {
    lower: MirrorRim,
    upper: MirrorRim,
    geometry: StereoGeometry,
}

/// What the stage keeps of the previous frame.
struct Previous {
    profile: AngularProfile,
    marks: Vec<RangedMark>,
}

/// Omnistereo from two conical mirror cameras.
pub struct OmnistereoStage {
    config: OmnistereoConfig,
    rig: StereoRig,
    landmarks: Vec<MapLandmark>,
    palette: Vec<[u8; 3]>,
    calibration: Option<Calibration>,
    previous: Option<Previous>,
}

impl OmnistereoStage {
    /// A stage for the rig `rig`, naming landmarks by the map's colours.
    pub fn new(
        config: OmnistereoConfig,
        rig: StereoRig,
        landmarks: &[MapLandmark],
    ) -> Result<Self, RobotError> {
        config.validate()?;
        if landmarks.is_empty() {
            return Err(RobotError::Missing(
                "omnistereo needs a map with landmarks (the world's pillars)".into(),
            ));
        }
        Ok(Self {
            config,
            rig,
            palette: landmarks.iter().map(|l| l.rgb).collect(),
            landmarks: landmarks.to_vec(),
            calibration: None,
            previous: None,
        })
    }

    /// Measures both rims and calibrates `v` by eq. (2).
    fn calibrate(&self, lower: &RgbaImage, upper: &RgbaImage) -> Result<Calibration, VisionError> {
        let (lo, up) = (MirrorRim::measure(lower)?, MirrorRim::measure(upper)?);
        let geometry = StereoGeometry::calibrate(
            self.rig.mirror_radius_mm,
            self.rig.tip_distance_mm,
            self.rig.separation_mm,
            &[lo, up],
        )?;
        Ok(Calibration {
            lower: lo,
            upper: up,
            geometry,
        })
    }

    /// The robot's pose from the pose of the mirrors' axis.
    fn robot_pose(&self, axis: Isometry2<f64>) -> Isometry2<f64> {
        let m = Vector2::from(self.rig.mount_mm);
        Isometry2::new(
            axis.translation.vector - axis.rotation * m,
            axis.rotation.angle(),
        )
    }

    fn trilateration(&self, ranged: &[RangedMark], out: &mut Perceived) {
        let seen: Vec<LandmarkRange> = ranged
            .iter()
            .map(|m| {
                let l = &self.landmarks[m.label];
                LandmarkRange {
                    centre_mm: l.centre_mm,
                    range_mm: m.range_mm + l.radius_mm,
                    bearing_rad: m.bearing_rad,
                    sigma_mm: m.sigma_mm,
                }
            })
            .collect();
        match trilaterate_with_error(&seen, self.config.trilateration) {
            Ok(fix) => out.fixes.push(Sighting {
                source: self.name(),
                measurement: Measurement::Pose {
                    pose: self.robot_pose(fix.pose),
                    alternative: None,
                    unambiguous: true,
                },
                quality: None,
                expected_error_mm: Some(fix.sigma_mm),
            }),
            Err(e) => out.not_found.push(NotFound {
                source: self.name(),
                reason: e.to_string(),
            }),
        }
    }

    /// The compass and the interframe translation against the previous frame.
    fn motion(&self, profile: &AngularProfile, ranged: &[RangedMark]) -> Option<MotionReading> {
        let prev = self.previous.as_ref()?;
        let rotation = profile
            .rotation_from(&prev.profile, &self.config.compass)
            .ok()?;
        let radius = |m: &RangedMark| self.landmarks[m.label].radius_mm;
        let pairs: Vec<FeaturePair> = ranged
            .iter()
            .filter_map(|now| {
                let then = prev.marks.iter().find(|p| p.label == now.label)?;
                Some(FeaturePair {
                    range_before_mm: then.range_mm + radius(then),
                    bearing_before_rad: then.bearing_rad,
                    range_after_mm: now.range_mm + radius(now),
                    bearing_after_rad: now.bearing_rad,
                    sigma_mm: then.sigma_mm.max(now.sigma_mm),
                })
            })
            .collect();
        let candidates = translation_candidates(&pairs, rotation.rotation_rad);
        let translation = densest_cluster(&candidates, self.config.cluster_sigmas).ok();
        Some(MotionReading {
            rotation_rad: rotation.rotation_rad,
            translation_mm: translation.map(|t| t.translation_mm),
            features: pairs.len(),
            inliers: translation.map_or(0, |t| t.inliers),
        })
    }
}

impl Stage for OmnistereoStage {
    fn name(&self) -> &'static str {
        NAME
    }

    fn cameras(&self) -> Vec<&str> {
        vec![&self.config.lower_sensor, &self.config.upper_sensor]
    }

    fn run(
        &mut self,
        obs: &Observation<'_>,
        _belief: &Belief,
        out: &mut Perceived,
    ) -> Result<(), RobotError> {
        let lower = image(obs, &self.config.lower_sensor, self.name())?;
        let upper = image(obs, &self.config.upper_sensor, self.name())?;
        let cal = match self.calibration {
            Some(c) => c,
            None => match self.calibrate(lower, upper) {
                Ok(c) => *self.calibration.insert(c),
                Err(e) => {
                    out.not_found.push(NotFound {
                        source: self.name(),
                        reason: format!("calibration (eq. (2)): {e}"),
                    });
                    return Ok(());
                }
            },
        };
        let marks = &self.config.marks;
        let lo = detect_marks(lower, &cal.lower, &self.palette, marks);
        let up = detect_marks(upper, &cal.upper, &self.palette, marks);
        let (ranged, _unranged) = range_marks(&cal.geometry, &lo, &up, self.config.radius_sigma_px);
        out.percepts.put(Landmarks(
            ranged
                .iter()
                .map(|m| LandmarkSighting {
                    landmark: m.label,
                    range_mm: m.range_mm,
                    bearing_rad: m.bearing_rad,
                })
                .collect(),
        ));
        self.trilateration(&ranged, out);
        let profile = AngularProfile::capture(
            &[(lower, &cal.lower), (upper, &cal.upper)],
            &self.config.compass,
        );
        if let Some(motion) = self.motion(&profile, &ranged) {
            out.percepts.put(motion);
        }
        self.previous = Some(Previous {
            profile,
            marks: ranged,
        });
        Ok(())
    }
}
