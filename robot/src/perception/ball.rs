//! The ball on the robot's own camera: each frame's sighting ([`omniloop_vision::ball`]: its
//! colour, its bearing, its range from where it meets the floor) fed to the robot's tracker
//! ([`crate::ball_tracker`]), which keeps it through frames where it is not seen and takes the
//! dribbler's light barrier when the body hides it.

use super::stage::{Belief, CameraNeed, FloorOptics, Perceived, PoseHistory, Stage, StageEntry};
use crate::RobotError;
use crate::ball_tracker::{BallTracker, TrackerConfig, sighting_covariance};
use crate::boundary::Observation;
use crate::config::RobotConfig;
use crate::estimates::NotFound;
use crate::percept::Percept;
use image::RgbaImage;
use nalgebra::{Isometry2, Matrix2, Point2, Vector2};
use omniloop_problem::Problems;
use omniloop_vision::ball::{
    BallColor, BallConfig, BallMiss, BallSighting, detect_forward, detect_mirror,
};
use serde::{Deserialize, Serialize};

/// The stage's name, in the estimates record and the registry.
pub const NAME: &str = "ball";

/// Its settings table, `[vision.ball]`.
const TABLE: &str = "ball";

/// The registry's entry.
pub const ENTRY: StageEntry = StageEntry {
    name: NAME,
    summary: "the ball by its colour, its range from where it meets the floor, tracked through \
              unseen frames and the dribbler's light barrier",
    pose_source: None,
    table: None,
    vision_table: Some(TABLE),
    check_vision: |v| v.tables.check("vision", TABLE, check_values),
    asked: |_| false,
    camera: CameraNeed::MirrorOrForward,
    world: &[],
    check: |_| Vec::new(),
    build: |c| Ok(Box::new(BallStage::new(c)?)),
};

/// `[vision.ball]`: the detector's and the tracker's settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BallSettings {
    /// The ball's colour.
    pub color: BallColor,
    /// The ball's radius, mm.
    pub radius_mm: f64,
    /// The fewest pixels taken for the ball.
    pub min_pixels: usize,
    /// Within this distance of the robot's centre the body hides the ball from its camera, mm
    /// (E1's robot: its 150 mm body of radius 90 mm hides the ball's top within 265 mm and its
    /// lower part to 341 mm, where sightings read a few per cent long: `omniloop replay
    /// ball_map`).
    pub blind_radius_mm: f64,
    /// The tracker.
    pub tracker: TrackerConfig,
}

impl Default for BallSettings {
    fn default() -> Self {
        let d = BallConfig::default();
        Self {
            color: d.color,
            radius_mm: d.radius_mm,
            min_pixels: d.min_pixels,
            blind_radius_mm: 300.0,
            tracker: TrackerConfig::default(),
        }
    }
}

/// `[vision.ball]`'s values, each problem naming its field.
fn check_values(s: &BallSettings, p: &mut Problems) {
    p.positive("radius_mm", s.radius_mm);
    if !s.blind_radius_mm.is_finite() || s.blind_radius_mm < 0.0 {
        p.fail("blind_radius_mm", "must be >= 0");
    }
    if s.min_pixels == 0 {
        p.fail("min_pixels", "must be >= 1");
    }
    let [lo, hi] = s.color.green_over_red;
    if !(0.0..=hi).contains(&lo) {
        p.fail(
            "color.green_over_red",
            format!("needs 0 <= lo <= hi (got [{lo}, {hi}])"),
        );
    }
    p.positive("tracker.accel_noise_mm2_s3", s.tracker.accel_noise_mm2_s3);
    p.positive("tracker.gate_sigmas", s.tracker.gate_sigmas);
    p.positive("tracker.max_unseen_s", s.tracker.max_unseen_s);
    if s.tracker.outliers_to_restart == 0 {
        p.fail("tracker.outliers_to_restart", "must be >= 1");
    }
    if s.tracker.roll_decel_mm_s2.is_nan() || s.tracker.roll_decel_mm_s2 < 0.0 {
        p.fail("tracker.roll_decel_mm_s2", "must be >= 0");
    }
}

/// Where the tracked ball came from this cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BallSource {
    /// The camera saw it.
    Camera,
    /// The dribbler's light barrier holds it.
    Dribbler,
    /// Neither: the tracker's prediction.
    Predicted,
}

/// What the robot believes of the ball this cycle.
#[derive(Debug, Clone, PartialEq)]
pub struct BallEstimate {
    /// This cycle's sighting (robot frame when its frame was taken), if the camera saw it.
    pub sighting: Option<BallSighting>,
    /// Where the ball is now, robot frame, mm.
    pub body_mm: Point2<f64>,
    /// Its velocity, robot frame, mm/s.
    pub velocity_body_mm_s: Vector2<f64>,
    /// Where it is, world frame, when the robot has a pose estimate.
    pub world_mm: Option<Point2<f64>>,
    /// One-sigma position error, mm.
    pub sigma_mm: f64,
    /// Where it came from.
    pub source: BallSource,
    /// Seconds since a measurement.
    pub age_s: f64,
}

impl Percept for BallEstimate {
    fn record(&self) -> Option<(&'static str, serde_json::Value)> {
        let xy = |p: Point2<f64>| [p.x, p.y];
        Some((
            NAME,
            serde_json::json!({
                "source": self.source,
                "body_mm": xy(self.body_mm),
                "velocity_body_mm_s": [self.velocity_body_mm_s.x, self.velocity_body_mm_s.y],
                "world_mm": self.world_mm.map(xy),
                "sigma_mm": self.sigma_mm,
                "age_s": self.age_s,
                "sighting": self.sighting.map(|s| serde_json::json!({
                    "range_mm": s.range_mm,
                    "bearing_rad": s.bearing_rad,
                    "range_sigma_mm": s.range_sigma_mm,
                    "bearing_sigma_rad": s.bearing_sigma_rad,
                    "pixels": s.pixels,
                })),
            }),
        ))
    }
}

/// Finds and tracks the ball on vision's camera.
pub struct BallStage {
    camera: String,
    optics: FloorOptics,
    settings: BallSettings,
    detector: BallConfig,
    tracker: BallTracker,
    /// Where the ball sits when the light barrier sees it, robot frame.
    dribbler_mm: Option<Point2<f64>>,
    /// The odometry poses of recent cycles.
    history: PoseHistory,
    /// Cycles in a row the track put the ball in the light barrier and it saw nothing.
    empty_barrier: u32,
}

/// Cycles the track may put the ball in the light barrier while the barrier sees nothing
/// before the track is dropped.
const EMPTY_BARRIER_CYCLES: u32 = 5;

impl BallStage {
    /// The stage on vision's camera of `config`: its mirror calibration, or its forward
    /// pinhole model.
    pub fn new(config: &RobotConfig) -> Result<Self, RobotError> {
        let (camera, optics) = FloorOptics::of(config, "ball perception")?;
        let settings: BallSettings = config.vision.table(TABLE)?;
        let detector = BallConfig {
            color: settings.color.clone(),
            radius_mm: settings.radius_mm,
            min_pixels: settings.min_pixels,
        };
        let dribbler_mm = config
            .body
            .kicker
            .map(|k| Point2::new(k.front_mm + settings.radius_mm, 0.0));
        Ok(Self {
            camera,
            optics,
            tracker: BallTracker::new(settings.tracker),
            settings,
            detector,
            dribbler_mm,
            history: PoseHistory::default(),
            empty_barrier: 0,
        })
    }

    /// The ball in one image, robot frame when it was taken.
    fn detect(&self, img: &RgbaImage) -> Result<BallSighting, BallMiss> {
        match &self.optics {
            FloorOptics::Mirror(cal) => detect_mirror(img, cal, &self.detector),
            FloorOptics::Forward(cam) => detect_forward(img, cam, &self.detector),
        }
    }

    /// How far the camera sees the floor, mm.
    fn view_range_mm(&self) -> f64 {
        match &self.optics {
            FloorOptics::Mirror(cal) => cal.samples.last().map_or(0.0, |s| s[1]),
            FloorOptics::Forward(_) => f64::INFINITY,
        }
    }

    /// Why the camera did not see the ball this cycle, knowing where the tracker puts it.
    fn miss_reason(&self, miss: &BallMiss, predicted_body: Option<Point2<f64>>) -> String {
        let Some(p) = predicted_body else {
            return miss.to_string();
        };
        let d = p.coords.norm();
        if d < self.settings.blind_radius_mm {
            format!("in the blind zone around the body (predicted at {d:.0} mm)")
        } else if d > self.view_range_mm() {
            format!("outside the view (predicted at {d:.0} mm)")
        } else if matches!(miss, BallMiss::NoBallColour) {
            format!("occluded (predicted at {d:.0} mm, no ball-coloured pixel)")
        } else {
            miss.to_string()
        }
    }

    /// Feeds the cycle's frame (if any) to the tracker; the reason it saw nothing otherwise.
    fn take_frame(
        &mut self,
        obs: &Observation<'_>,
        now: &Isometry2<f64>,
    ) -> (Option<BallSighting>, Option<String>) {
        let Some(frame) = obs.frame(&self.camera) else {
            return (
                None,
                Some(format!("no frame of camera {:?} this cycle", self.camera)),
            );
        };
        match self.detect(frame.image) {
            Ok(s) => {
                let taken = self.history.at(frame.t_s).unwrap_or(*now);
                let z = taken * s.position_mm;
                let r = sighting_covariance(
                    &taken,
                    s.range_mm,
                    s.bearing_rad,
                    s.range_sigma_mm,
                    s.bearing_sigma_rad,
                );
                // A late frame's ball has rolled on since: move it by the track's velocity.
                let lag = obs.t_s - frame.t_s;
                let v = self
                    .tracker
                    .track()
                    .map_or(Vector2::zeros(), |t| t.velocity());
                self.tracker.update(obs.t_s, z + v * lag, r, None);
                (Some(s), None)
            }
            Err(miss) => {
                let predicted = self.tracker.track().map(|t| now.inverse() * t.position());
                (None, Some(self.miss_reason(&miss, predicted)))
            }
        }
    }

    /// Whether the track has put the ball where the light barrier would see it for
    /// [`EMPTY_BARRIER_CYCLES`] cycles in a row while it saw nothing.
    fn missed_at_dribbler(&mut self, now: &Isometry2<f64>) -> bool {
        let inside = match (self.dribbler_mm, self.tracker.track()) {
            (Some(at), Some(track)) => {
                let p = now.inverse() * track.position();
                p.x <= at.x + 1.0 && p.x > at.x - 20.0 && p.y.abs() < 15.0
            }
            _ => false,
        };
        self.empty_barrier = if inside { self.empty_barrier + 1 } else { 0 };
        self.empty_barrier >= EMPTY_BARRIER_CYCLES
    }

    /// The light barrier's measurement: the ball at the dribbler, moving with it.
    fn take_dribbler(&mut self, t_s: f64, now: &Isometry2<f64>) {
        let Some(at) = self.dribbler_mm else {
            return;
        };
        let z = now * at;
        let v = match self.history.back(1) {
            Some((t0, p0)) if t_s > t0 => (z - p0 * at) / (t_s - t0),
            _ => Vector2::zeros(),
        };
        self.tracker
            .update(t_s, z, Matrix2::identity() * 25.0, Some(v));
    }
}

impl Stage for BallStage {
    fn name(&self) -> &'static str {
        NAME
    }

    fn cameras(&self) -> Vec<&str> {
        vec![self.camera.as_str()]
    }

    fn carried(&mut self) {
        self.tracker.reset();
        self.history.clear();
    }

    fn runs_without_frames(&self) -> bool {
        true
    }

    fn run(
        &mut self,
        obs: &Observation<'_>,
        belief: &Belief,
        out: &mut Perceived,
    ) -> Result<(), RobotError> {
        let now = belief.odometry_pose;
        self.history.push(obs.t_s, now, 1.0);
        self.tracker.predict(obs.t_s);
        let (sighting, missed) = self.take_frame(obs, &now);
        let held = obs.ball_in_dribbler();
        if held {
            self.take_dribbler(obs.t_s, &now);
        } else if self.missed_at_dribbler(&now) {
            // Predicted on the dribbler, yet the light barrier sees nothing: it is not there.
            self.tracker.reset();
            out.not_found.push(NotFound {
                source: NAME,
                reason: "not at the dribbler where predicted".to_string(),
            });
            return Ok(());
        }
        if let Some(reason) = missed.filter(|_| !held) {
            out.not_found.push(NotFound {
                source: NAME,
                reason,
            });
        }
        let Some(track) = self.tracker.track() else {
            return Ok(());
        };
        let to_body = now.inverse();
        let body_mm = to_body * track.position();
        let source = match (held, sighting.is_some()) {
            (true, _) => BallSource::Dribbler,
            (false, true) => BallSource::Camera,
            (false, false) => BallSource::Predicted,
        };
        out.percepts.put(BallEstimate {
            sighting,
            body_mm,
            velocity_body_mm_s: to_body * track.velocity(),
            world_mm: belief.pose.map(|p| p * body_mm),
            sigma_mm: track.position_sigma_mm(),
            source,
            age_s: obs.t_s - track.last_seen_s,
        });
        Ok(())
    }
}
