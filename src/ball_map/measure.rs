//! The map's frames: the robot stands still, the ball is put at a distance and direction, vision's
//! camera takes a frame with its noise, and the detector's answer is kept beside the truth;
//! or, without a ball, the robot is carried to seeded random poses and every frame should show
//! none. Where the robot's body hides the ball comes from the camera's own rays.

use super::spec::BallMapSpec;
use crate::run::{RunError, Simulation};
use crate::scenario::Scenario;
use image::RgbaImage;
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_control::wrap_pi;
use omniloop_robot::perception::ball::BallSettings;
use omniloop_sim::SimError;
use omniloop_vision::RadialCalibration;
use omniloop_vision::ball::{BallConfig, BallMiss, BallSighting, detect_mirror};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// How much of the ball the robot's body hides from its camera.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Occlusion {
    /// The body hides the ball's top: the ball is out of sight.
    Hidden,
    /// The body hides the ball's lower part (its near edge on the image).
    Partial,
    /// The whole ball is in view.
    Clear,
}

impl Occlusion {
    /// Its name in the CSV and the tables.
    pub fn name(self) -> &'static str {
        match self {
            Occlusion::Hidden => "hidden",
            Occlusion::Partial => "partly hidden",
            Occlusion::Clear => "in view",
        }
    }
}

/// Where the body hides the ball, from the ray of the camera that grazes the body's top edge.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BodyShadow {
    /// Within this distance of the robot's centre the body hides the ball's top, mm.
    pub hidden_mm: f64,
    /// Beyond this distance the whole ball is in view, mm.
    pub clear_mm: f64,
    /// The grazing ray's depression below the horizontal, degrees.
    pub grazing_depression_deg: f64,
}

impl BodyShadow {
    /// The shadow of a body of radius `body_mm` and height `height_mm` on a ball of radius
    /// `ball_mm`, through the calibration's floor map and elevation column (the camera's axis
    /// taken at the robot's centre); `None` when no ray of the camera reaches the floor past
    /// the body.
    pub fn of(cal: &RadialCalibration, body_mm: f64, height_mm: f64, ball_mm: f64) -> Option<Self> {
        // A ray that meets the floor at r with depression a is at (r - x) tan(a) over x.
        let above_edge = |big_r: f64| {
            let r = cal.floor_distance_mm(big_r)?;
            let t = (-cal.elevation_rad(big_r)?).tan();
            (t > 0.0 && r > body_mm).then_some(((r - body_mm) * t, t))
        };
        let grazing = cal
            .samples
            .windows(2)
            .find_map(|w| {
                let (a, b) = (above_edge(w[0][0])?, above_edge(w[1][0])?);
                (a.0 < height_mm && b.0 >= height_mm).then(|| {
                    let u = (height_mm - a.0) / (b.0 - a.0);
                    a.1 + u * (b.1 - a.1)
                })
            })
            .or_else(|| {
                let first = cal.samples.iter().find_map(|s| above_edge(s[0]))?;
                (first.0 >= height_mm).then_some(first.1)
            })?;
        let t = grazing;
        Some(Self {
            hidden_mm: body_mm + (height_mm - 2.0 * ball_mm) / t,
            clear_mm: body_mm + (height_mm - ball_mm + ball_mm * t.hypot(1.0)) / t,
            grazing_depression_deg: t.atan().to_degrees(),
        })
    }

    /// How much of a ball centred `d` from the robot's centre the body hides.
    pub fn occlusion(&self, d: f64) -> Occlusion {
        if d < self.hidden_mm {
            Occlusion::Hidden
        } else if d < self.clear_mm {
            Occlusion::Partial
        } else {
            Occlusion::Clear
        }
    }
}

/// What the detector reported in one frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Seen {
    /// The ball's centre, robot frame, mm.
    pub position_mm: [f64; 2],
    /// Its range, mm.
    pub range_mm: f64,
    /// Its bearing, degrees.
    pub bearing_deg: f64,
    /// Pixels in the blob.
    pub pixels: usize,
}

/// One frame of the map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrameRow {
    /// The ring's distance, mm (0 for a ball-free frame).
    pub distance_mm: f64,
    /// The direction's index around the robot.
    pub direction: usize,
    /// The draw at that place.
    pub draw: usize,
    /// The robot's true pose: x, y (mm), heading (degrees).
    pub robot: [f64; 3],
    /// The ball's centre in the robot frame, mm (`None`: a ball-free frame).
    pub truth_mm: Option<[f64; 2]>,
    /// How much of the ball the body hides (`None`: no ball, or no shadow known).
    pub occlusion: Option<Occlusion>,
    /// What the detector saw, if anything.
    pub seen: Option<Seen>,
    /// Why it saw nothing.
    pub miss: Option<String>,
}

impl FrameRow {
    /// Whether the body leaves the ball in sight (not [`Occlusion::Hidden`]).
    pub fn unoccluded(&self) -> bool {
        self.occlusion != Some(Occlusion::Hidden)
    }

    /// The true range, mm.
    pub fn true_range_mm(&self) -> Option<f64> {
        self.truth_mm.map(|t| t[0].hypot(t[1]))
    }

    /// The true bearing, degrees.
    pub fn true_bearing_deg(&self) -> Option<f64> {
        self.truth_mm.map(|t| t[1].atan2(t[0]).to_degrees())
    }

    /// Seen range less true range, mm.
    pub fn range_error_mm(&self) -> Option<f64> {
        Some(self.seen.as_ref()?.range_mm - self.true_range_mm()?)
    }

    /// The range error's size, percent of the true range.
    pub fn range_error_pct(&self) -> Option<f64> {
        Some(100.0 * self.range_error_mm()?.abs() / self.true_range_mm()?)
    }

    /// Seen bearing less true bearing, degrees, in (-180, 180].
    pub fn bearing_error_deg(&self) -> Option<f64> {
        let d = self.seen.as_ref()?.bearing_deg - self.true_bearing_deg()?;
        Some(wrap_pi(d.to_radians()).to_degrees())
    }
}

/// The frames of one run and what they were taken with.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// Vision's camera (the sensor's name).
    pub camera: String,
    /// Its image, width and height in pixels.
    pub image_px: [u32; 2],
    /// Where the body hides the ball.
    pub shadow: Option<BodyShadow>,
    /// Every frame, in the order taken.
    pub rows: Vec<FrameRow>,
}

/// The seed of the placements' draws, derived from the run's seed.
fn placement_seed(seed: u64) -> u64 {
    seed ^ 0xBA11_3A90_77C4_D21E
}

/// The detector's settings: the scenario's `[vision.ball]` (its colour, radius, fewest pixels).
pub fn detector_config(s: &Scenario) -> Result<BallConfig, RunError> {
    let settings: BallSettings = s.vision.table("ball")?;
    Ok(BallConfig {
        color: settings.color,
        radius_mm: settings.radius_mm,
        min_pixels: settings.min_pixels,
    })
}

/// Takes every frame of the map (`progress(frames done, frames)` as it goes): the placed
/// balls with a ball in the world, the ball-free frames without.
pub fn run(
    sim: &mut Simulation,
    spec: &BallMapSpec,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Measured, RunError> {
    let s = sim.scenario().clone();
    let config = detector_config(&s)?;
    let cal = sim.vision_calibration().cloned().ok_or_else(|| {
        SimError::Invalid("the ball map needs the robot's vision camera, calibrated".into())
    })?;
    let ball_mm = s
        .world
        .ball
        .as_ref()
        .map_or(config.radius_mm, |b| b.radius_mm);
    let shadow = BodyShadow::of(&cal, s.robot.radius_mm, s.robot.height_mm, ball_mm);
    let mut rng = StdRng::seed_from_u64(placement_seed(s.seed));
    let mut frame = Framer {
        sim,
        cal: &cal,
        config: &config,
    };
    let rows = if s.world.ball.is_some() {
        placed(&mut frame, &s, spec, shadow.as_ref(), &mut rng, progress)?
    } else {
        empty(&mut frame, &s, spec, &mut rng, progress)?
    };
    Ok(Measured {
        camera: cal.sensor.clone(),
        image_px: [cal.width_px, cal.height_px],
        shadow,
        rows,
    })
}

/// Renders and reads frames.
struct Framer<'a> {
    sim: &'a mut Simulation,
    cal: &'a RadialCalibration,
    config: &'a BallConfig,
}

impl Framer<'_> {
    /// The robot at `pose`, the ball (if any) at `ball` in the robot frame: one frame, read.
    fn take(
        &mut self,
        pose: Isometry2<f64>,
        ball: Option<Point2<f64>>,
    ) -> Result<Result<BallSighting, BallMiss>, RunError> {
        self.sim.place_robot(pose);
        if let Some(b) = ball {
            self.sim.place_ball(pose * b, Vector2::zeros())?;
        }
        let img: &RgbaImage = self
            .sim
            .vision_frame()?
            .ok_or_else(|| SimError::Invalid("the robot's vision camera is not rendered".into()))?;
        Ok(detect_mirror(img, self.cal, self.config))
    }
}

/// The ball at every distance, direction and draw around the robot standing at its start.
fn placed(
    frame: &mut Framer<'_>,
    s: &Scenario,
    spec: &BallMapSpec,
    shadow: Option<&BodyShadow>,
    rng: &mut StdRng,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Vec<FrameRow>, RunError> {
    let centre = s.start().point();
    let step = TAU / spec.directions as f64;
    let total = spec.frames(true) as u64;
    let mut rows = Vec::with_capacity(total as usize);
    for &d in &spec.distances_mm {
        for direction in 0..spec.directions {
            for draw in 0..spec.draws {
                let heading = rng.random_range(0.0..TAU);
                let bearing = direction as f64 * step + rng.random_range(0.0..step);
                let truth = Point2::new(d * bearing.cos(), d * bearing.sin());
                let pose = Isometry2::new(centre.coords, heading);
                let result = frame.take(pose, Some(truth))?;
                rows.push(row(d, direction, draw, &pose, Some(truth), shadow, result));
                progress(rows.len() as u64, total);
            }
        }
    }
    Ok(rows)
}

/// Ball-free frames at seeded random poses where the body stands clear on the floor.
fn empty(
    frame: &mut Framer<'_>,
    s: &Scenario,
    spec: &BallMapSpec,
    rng: &mut StdRng,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Vec<FrameRow>, RunError> {
    let total = spec.empty_frames as u64;
    let mut rows = Vec::with_capacity(spec.empty_frames);
    for k in 0..spec.empty_frames {
        let pose = random_pose(s, spec.clearance_mm, rng)?;
        let result = frame.take(pose, None)?;
        rows.push(row(0.0, k, 0, &pose, None, None, result));
        progress(rows.len() as u64, total);
    }
    Ok(rows)
}

/// A pose drawn uniformly over the floor region's bounding box, kept where the body stands on
/// the floor clear of every solid by `clearance_mm`.
fn random_pose(
    s: &Scenario,
    clearance_mm: f64,
    rng: &mut StdRng,
) -> Result<Isometry2<f64>, RunError> {
    let layout = &s.world;
    let (mut lo, mut hi) = (
        Point2::new(f64::MAX, f64::MAX),
        Point2::new(f64::MIN, f64::MIN),
    );
    for r in layout.all_floor_rects() {
        let half = 0.5 * r.size_mm[0].hypot(r.size_mm[1]);
        lo = lo.inf(&Point2::new(r.center_mm[0] - half, r.center_mm[1] - half));
        hi = hi.sup(&Point2::new(r.center_mm[0] + half, r.center_mm[1] + half));
    }
    if lo.x >= hi.x || lo.y >= hi.y {
        return Err(SimError::Invalid("ball-free poses need a bounded floor region".into()).into());
    }
    let body = s.robot.radius_mm + clearance_mm;
    let solids = layout.solids();
    let fits = |p: Point2<f64>| {
        let rim = (0..16).map(|k| {
            let a = f64::from(k) / 16.0 * TAU;
            p + Vector2::new(a.cos(), a.sin()) * body
        });
        layout.is_floor(p)
            && rim.clone().all(|q| layout.is_floor(q))
            && solids.iter().all(|o| o.shape.distance_mm(p) >= body)
    };
    for _ in 0..10_000 {
        let p = Point2::new(rng.random_range(lo.x..hi.x), rng.random_range(lo.y..hi.y));
        if fits(p) {
            return Ok(Isometry2::new(p.coords, rng.random_range(0.0..TAU)));
        }
    }
    Err(SimError::Invalid("no pose on the floor leaves the robot's body clear".into()).into())
}

/// One frame's row.
fn row(
    distance_mm: f64,
    direction: usize,
    draw: usize,
    pose: &Isometry2<f64>,
    truth: Option<Point2<f64>>,
    shadow: Option<&BodyShadow>,
    result: Result<BallSighting, BallMiss>,
) -> FrameRow {
    let (seen, miss) = match result {
        Ok(s) => (
            Some(Seen {
                position_mm: [s.position_mm.x, s.position_mm.y],
                range_mm: s.range_mm,
                bearing_deg: s.bearing_rad.to_degrees(),
                pixels: s.pixels,
            }),
            None,
        ),
        Err(m) => (None, Some(m.to_string())),
    };
    FrameRow {
        distance_mm,
        direction,
        draw,
        robot: [
            pose.translation.x,
            pose.translation.y,
            pose.rotation.angle().to_degrees(),
        ],
        truth_mm: truth.map(|t| [t.x, t.y]),
        occlusion: truth.and_then(|t| Some(shadow?.occlusion(t.coords.norm()))),
        seen,
        miss,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A single-viewpoint camera `h` mm up: image radius `R` sees the floor at `10 R`.
    fn viewpoint(h: f64) -> RadialCalibration {
        let samples: Vec<[f64; 2]> = (0..=400).map(|k| [k as f64, 10.0 * k as f64]).collect();
        let elevation = (1..=400)
            .map(|k| [k as f64, -(h / (10.0 * k as f64)).atan()])
            .collect();
        RadialCalibration {
            sensor: "omni".into(),
            width_px: 801,
            height_px: 801,
            principal_point_px: [400.5, 400.5],
            mount_mm: [0.0, 0.0],
            samples,
            horizon_px: 400.0,
            elevation,
            fit: None,
        }
    }

    #[test]
    fn the_shadow_of_e1s_body_is_where_its_top_edge_puts_it() {
        let s = BodyShadow::of(&viewpoint(205.08), 90.0, 150.0, 21.5).unwrap();
        // The ray over the edge at (90, 150) from (0, 205.08) passes 43 mm up at 264.8 mm.
        assert!((s.hidden_mm - 264.8).abs() < 1.0, "{s:?}");
        // ... and clears the whole ball from 341 mm.
        assert!((s.clear_mm - 341.2).abs() < 1.0, "{s:?}");
        assert_eq!(s.occlusion(200.0), Occlusion::Hidden);
        assert_eq!(s.occlusion(300.0), Occlusion::Partial);
        assert_eq!(s.occlusion(400.0), Occlusion::Clear);
        // A viewpoint under the body's top sees no floor past it.
        assert!(BodyShadow::of(&viewpoint(140.0), 90.0, 150.0, 21.5).is_none());
    }

    #[test]
    fn a_rows_errors_are_against_the_truth() {
        let r = FrameRow {
            distance_mm: 500.0,
            direction: 0,
            draw: 0,
            robot: [0.0, 0.0, 0.0],
            truth_mm: Some([0.0, -500.0]),
            occlusion: Some(Occlusion::Clear),
            seen: Some(Seen {
                position_mm: [0.0, 0.0],
                range_mm: 510.0,
                bearing_deg: 179.0,
                pixels: 9,
            }),
            miss: None,
        };
        assert!((r.range_error_mm().unwrap() - 10.0).abs() < 1e-9);
        assert!((r.range_error_pct().unwrap() - 2.0).abs() < 1e-9);
        // 179 against -90: wrapped to -91.
        assert!((r.bearing_error_deg().unwrap() + 91.0).abs() < 1e-9);
        assert!(r.unoccluded());
    }
}
