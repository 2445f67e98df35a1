//! Self-location from three striped marks (Ishikawa, Kikuchi and Kato, Sect. 3.3, Fig. 4):
//! while the pose is unknown the robot turns its camera to the right stop (-180 degrees), pans
//! from right to left recognizing the marks in each frame (Sect. 3.4), and once it has the
//! directions of all three computes its position (Sect. 3.1). If a mark was not found (seen
//! edge-on, hidden) it moves to another observation point and searches again.
//!
//! Where the paper is silent we chose:
//! - a mark's bearing is the pan angle of the frame plus the direction of the mark's centre
//!   column (Sect. 3.2), averaged over the frames that show it within `central_fraction` of
//!   the half-image from the axis; the sweep ends once every mark has been seen and has left
//!   the view again, or at the left stop;
//! - the frame's pan angle is the pan unit's reading when the frame was taken: a frame that
//!   arrives late was taken at an earlier angle (60 degrees/s for 30 ms is 1.8 degrees), so
//!   the readings of the last cycles are kept and interpolated at the frame's time;
//! - the other observation point is `move_mm` away, square to the middle of the widest gap
//!   between the bearings of the marks that were found (where the missing one must be) and to
//!   its left, so that the line of sight to it moves past what hides it; straight ahead when
//!   none was found. The robot drives there on its wheels' dead reckoning;
//! - the second mark of the map is the one both circles pass through (the paper's Q);
//! - with an omnidirectional camera (beyond the paper) one frame shows all three marks, read
//!   on rings of the image instead of rows, and nothing pans.

use super::stage::{
    Belief, CameraNeed, ObservationPoint, Perceived, Sighting, Stage, StageEntry, WorldNeed, image,
    vision_camera, vision_settings,
};
use crate::RobotError;
use crate::boundary::{ActuatorCommand, ActuatorState, Observation};
use crate::config::{MapMark, RobotConfig};
use crate::estimates::{Measurement, NotFound};
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_problem::{Problem, Problems};
use omniloop_vision::RadialCalibration;
use omniloop_vision::resection::{
    ColumnCalibration, MarkBearing, ResectionConfig, StripePattern, find_marks, find_marks_ring,
    resect, ring_bearing_rad,
};
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// The stage's name, in the estimates record and the registry.
pub const NAME: &str = "resection";

/// The `control.pose_source` under which its fixes correct the estimate.
pub const POSE_SOURCE: &str = "resection";

/// The registry's entry.
pub const ENTRY: StageEntry = StageEntry {
    name: NAME,
    summary: "three-mark resection: a panning search for the striped marks, then one fix \
              (Ishikawa, Kikuchi and Kato)",
    pose_source: Some(POSE_SOURCE),
    table: Some("resection"),
    vision_table: Some("resection"),
    check_vision: |v| {
        v.tables
            .check::<ResectionConfig>("vision", "resection", |t, p| {
                if let Err(e) = t.validate() {
                    p.fail("", e.to_string());
                }
            })
    },
    asked: |c| c.control.pose_source == POSE_SOURCE,
    camera: CameraNeed::MirrorOrPinhole,
    world: &[WorldNeed::ResectionCamera],
    check,
    build: |c| Ok(Box::new(build(c)?)),
};

/// `[control.resection]` and the map's marks.
fn check(c: &RobotConfig) -> Vec<Problem> {
    let mut out = Vec::new();
    match c.control.table::<SearchConfig>("resection") {
        Err(e) => out.push(e),
        Ok(r) => {
            let mut p = Problems::under("control.resection");
            p.positive("pan_rate_deg_s", r.pan_rate_deg_s);
            p.positive("move_mm", r.move_mm);
            if !(r.central_fraction > 0.0 && r.central_fraction <= 1.0) {
                let why = format!("must be in (0, 1] (got {})", r.central_fraction);
                p.fail("central_fraction", why);
            }
            out.extend(p);
        }
    }
    if c.map.marks.len() != 3 {
        let why = format!(
            "resection needs exactly three marks: name three [[world.boards]] (found {})",
            c.map.marks.len()
        );
        out.push(Problem::new("control.pose_source", why));
    }
    out
}

/// The resection stage on vision's camera: panning with a pinhole's column calibration, or
/// from one image of a mirror camera.
fn build(config: &RobotConfig) -> Result<ResectionStage, RobotError> {
    let camera = vision_camera(config, "resection")?;
    let view = match (config.columns(camera), config.calibration(camera)) {
        (Some(c), _) => View::Pan(c.clone()),
        (None, Some(c)) => View::Ring(c.clone()),
        (None, None) => {
            return Err(RobotError::Missing(format!(
                "no column or mirror calibration for camera {camera:?}"
            )));
        }
    };
    let search = config.control.table("resection")?;
    let vision = vision_settings(config, "resection")?;
    ResectionStage::new(camera, view, vision, search, &config.map.marks)
}

/// How the robot searches for the three marks (`[control.resection]`, Fig. 4 of the resection
/// paper).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SearchConfig {
    /// Rate of the pan from right to left, deg/s (the pan unit clips it to its limit).
    pub pan_rate_deg_s: f64,
    /// Sightings count toward a mark's bearing when its centre is within this fraction of the
    /// half-width of the image from the optical axis (ours: the calibration is best there).
    pub central_fraction: f64,
    /// Length of the move to another observation point when a mark was not found, mm.
    pub move_mm: f64,
    /// Moves before the robot gives up.
    pub max_moves: u32,
}

impl Default for SearchConfig {
    fn default() -> Self {
        Self {
            pan_rate_deg_s: 60.0,
            central_fraction: 0.5,
            move_mm: 300.0,
            max_moves: 3,
        }
    }
}

/// The words of the stage's last "not found" when it stops searching.
pub const GAVE_UP: &str = "gave up";

/// How the stage's camera turns image positions into bearings.
pub enum View {
    /// A pinhole camera on a pan unit, with its column calibration.
    Pan(ColumnCalibration),
    /// An omnidirectional mirror camera, with its image-to-scene calibration.
    Ring(RadialCalibration),
}

/// Where the search stands.
#[derive(Debug, Clone, PartialEq)]
enum State {
    /// The pose is unknown: search.
    Start,
    /// Turning the camera to the right stop.
    Aim,
    /// Panning right to left.
    Sweep(Vec<Track>),
    /// Driving to another observation point (odometry frame).
    Move(Point2<f64>),
    /// Located, or given up, until the robot is carried again.
    Done,
}

/// What a sweep saw of one mark.
#[derive(Debug, Clone, Default, PartialEq)]
struct Track {
    /// Bearings (robot frame) of its central sightings, rad.
    bearings: Vec<f64>,
    /// Whether the last frame showed it.
    visible: bool,
}

impl Track {
    /// Seen near the axis and out of view again.
    fn complete(&self) -> bool {
        !self.bearings.is_empty() && !self.visible
    }

    /// The mean of the central bearings.
    fn bearing(&self) -> Option<f64> {
        let first = *self.bearings.first()?;
        let n = self.bearings.len() as f64;
        Some(first + self.bearings.iter().map(|b| wrap(b - first)).sum::<f64>() / n)
    }
}

/// The resection stage.
pub struct ResectionStage {
    camera: String,
    view: View,
    mount_mm: Vector2<f64>,
    config: ResectionConfig,
    search: SearchConfig,
    marks: Vec<MapMark>,
    patterns: Vec<StripePattern>,
    state: State,
    moves: u32,
    pans: PanHistory,
}

/// The pan unit's readings of the last cycles, to know the angle at which a late frame was
/// taken.
#[derive(Debug, Clone, Default, PartialEq)]
struct PanHistory {
    /// (time s, pan rad), oldest first.
    readings: std::collections::VecDeque<(f64, f64)>,
}

impl PanHistory {
    /// Readings kept: a second of cycles at 40 ms and more.
    const KEPT: usize = 32;

    fn record(&mut self, t_s: f64, pan_rad: f64) {
        match self.readings.back() {
            Some(&(t, _)) if t == t_s => {
                self.readings.pop_back();
            }
            Some(&(t, _)) if t > t_s => self.readings.clear(),
            _ => {}
        }
        self.readings.push_back((t_s, pan_rad));
        if self.readings.len() > Self::KEPT {
            self.readings.pop_front();
        }
    }

    /// The pan at `t_s`, linear between the readings around it; the oldest or newest reading
    /// outside them (none without readings).
    fn at(&self, t_s: f64) -> Option<f64> {
        let (&(t0, p0), &(t1, p1)) = (self.readings.front()?, self.readings.back()?);
        if t_s <= t0 {
            return Some(p0);
        }
        if t_s >= t1 {
            return Some(p1);
        }
        let k = self.readings.iter().position(|&(t, _)| t >= t_s)?;
        let ((ta, pa), (tb, pb)) = (self.readings[k - 1], self.readings[k]);
        Some(pa + (pb - pa) * (t_s - ta) / (tb - ta))
    }
}

impl ResectionStage {
    /// A stage searching with `camera` for the map's three `marks`.
    pub fn new(
        camera: &str,
        view: View,
        config: ResectionConfig,
        search: SearchConfig,
        marks: &[MapMark],
    ) -> Result<Self, RobotError> {
        config.validate()?;
        if marks.len() != 3 {
            return Err(RobotError::Missing(format!(
                "resection needs exactly three marks on the map (named boards), found {}",
                marks.len()
            )));
        }
        for m in marks {
            m.pattern.validate()?;
        }
        let mount = match &view {
            View::Pan(c) => c.mount_mm,
            View::Ring(c) => c.mount_mm,
        };
        Ok(Self {
            camera: camera.to_string(),
            view,
            mount_mm: Vector2::from(mount),
            patterns: marks.iter().map(|m| m.pattern.clone()).collect(),
            marks: marks.to_vec(),
            config,
            search,
            state: State::Start,
            moves: 0,
            pans: PanHistory::default(),
        })
    }

    /// Pan the camera at `rate_rad_s`.
    fn pan_at(&self, rate_rad_s: f64) -> ActuatorCommand {
        ActuatorCommand::PanAt {
            sensor: self.camera.clone(),
            rate_rad_s,
        }
    }

    /// The pan angle of the camera, from the actuators' state.
    fn pan_rad(&self, obs: &Observation<'_>) -> Result<f64, RobotError> {
        obs.actuators
            .iter()
            .find_map(|a| match a {
                ActuatorState::Pan { sensor, pan_rad } if *sensor == self.camera => Some(*pan_rad),
                _ => None,
            })
            .ok_or_else(|| {
                RobotError::Missing(format!(
                    "resection pans camera {:?}, which is not on a pan unit",
                    self.camera
                ))
            })
    }

    /// One frame of the sweep: the marks in view and their bearings.
    fn sweep_frame(
        &self,
        tracks: &mut [Track],
        obs: &Observation<'_>,
        cal: &ColumnCalibration,
    ) -> Result<f64, RobotError> {
        let now = self.pan_rad(obs)?;
        let img = image(obs, &self.camera, NAME)?;
        let pan = obs
            .frame(&self.camera)
            .and_then(|f| self.pans.at(f.t_s))
            .unwrap_or(now);
        let seen = find_marks(img, &self.patterns, &self.config).unwrap_or_default();
        let half = 0.5 * cal.width_px as f64 * self.search.central_fraction;
        for (k, t) in tracks.iter_mut().enumerate() {
            let s = seen.iter().find(|s| s.mark == k);
            t.visible = s.is_some();
            if let Some(s) = s.filter(|s| (s.centre - cal.axis_column_px).abs() <= half) {
                t.bearings.push(wrap(pan + cal.bearing_rad(s.centre)));
            }
        }
        Ok(now)
    }

    /// The bearings of the marks in one omnidirectional frame.
    fn ring_look(
        &self,
        obs: &Observation<'_>,
        cal: &RadialCalibration,
    ) -> Result<Vec<Option<f64>>, RobotError> {
        let img = image(obs, &self.camera, NAME)?;
        let seen = find_marks_ring(img, cal, &self.patterns, &self.config).unwrap_or_default();
        let n = self.config.ring_samples;
        Ok((0..self.marks.len())
            .map(|k| {
                seen.iter()
                    .find(|s| s.mark == k)
                    .map(|s| wrap(ring_bearing_rad(s.centre, n)))
            })
            .collect())
    }

    /// The search is over with these bearings: a fix, or a move to another point.
    fn conclude(&mut self, bearings: &[Option<f64>], belief: &Belief, out: &mut Perceived) {
        let missing: Vec<&str> = self
            .marks
            .iter()
            .zip(bearings)
            .filter(|(_, b)| b.is_none())
            .map(|(m, _)| m.pattern.name.as_str())
            .collect();
        let why = if missing.is_empty() {
            let mb = |k: usize| MarkBearing {
                position: self.marks[k].centre_mm,
                bearing_rad: bearings[k].unwrap_or_default(),
            };
            match resect(&mb(0), &mb(1), &mb(2)) {
                Ok(r) => {
                    // The bearings are the camera axis's; the robot's centre is off it by the
                    // mount.
                    let pose = Isometry2::new(r.position.coords, r.heading_rad);
                    let centre = pose * Point2::from(-self.mount_mm);
                    out.fixes.push(Sighting {
                        source: NAME,
                        measurement: Measurement::Pose {
                            pose: Isometry2::new(centre.coords, r.heading_rad),
                            alternative: None,
                            unambiguous: true,
                        },
                        quality: None,
                        expected_error_mm: None,
                    });
                    self.state = State::Done;
                    return;
                }
                Err(e) => e.to_string(),
            }
        } else {
            format!("mark {} not found", missing.join(", "))
        };
        if self.moves >= self.search.max_moves {
            out.not_found.push(NotFound {
                source: NAME,
                reason: format!("{why}; {GAVE_UP} after {} moves", self.moves),
            });
            self.state = State::Done;
            return;
        }
        out.not_found.push(NotFound {
            source: NAME,
            reason: format!("{why}: moving {} mm to look again", self.search.move_mm),
        });
        let dir = move_direction(bearings);
        let here = belief.odometry_pose;
        let step = Vector2::new(dir.cos(), dir.sin()) * self.search.move_mm;
        self.moves += 1;
        self.state = State::Move(here * Point2::from(step));
    }
}

/// The direction of the move to another observation point (robot frame): square to the left of
/// the middle of the widest gap between the found bearings; ahead when none was found.
fn move_direction(bearings: &[Option<f64>]) -> f64 {
    let mut found: Vec<f64> = bearings
        .iter()
        .flatten()
        .map(|b| b.rem_euclid(TAU))
        .collect();
    if found.is_empty() {
        return 0.0;
    }
    found.sort_by(f64::total_cmp);
    let n = found.len();
    let (mut gap, mut middle) = (-1.0, 0.0);
    for i in 0..n {
        let (a, b) = (found[i], found[(i + 1) % n]);
        let g = (b - a).rem_euclid(TAU);
        let g = if g == 0.0 { TAU } else { g };
        if g > gap {
            gap = g;
            middle = a + 0.5 * g;
        }
    }
    wrap(middle + 0.5 * PI)
}

/// `a` wrapped into `(-pi, pi]`.
fn wrap(a: f64) -> f64 {
    let w = a.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

/// The pan angle at which the camera is at its right stop.
const RIGHT_STOP: f64 = -PI + 1e-3;

impl Stage for ResectionStage {
    fn name(&self) -> &'static str {
        NAME
    }

    fn cameras(&self) -> Vec<&str> {
        vec![&self.camera]
    }

    fn carried(&mut self) {
        self.state = State::Start;
        self.moves = 0;
    }

    /// No frames while driving to another observation point or after the fix (a move that
    /// arrives starts its search with the next cycle's frames).
    fn wants_frames(&self) -> bool {
        !matches!(self.state, State::Move(_) | State::Done)
    }

    fn run(
        &mut self,
        obs: &Observation<'_>,
        belief: &Belief,
        out: &mut Perceived,
    ) -> Result<(), RobotError> {
        if matches!(self.view, View::Pan(_)) {
            let pan = self.pan_rad(obs)?;
            self.pans.record(obs.t_s, pan);
        }
        match std::mem::replace(&mut self.state, State::Done) {
            State::Done => {}
            State::Start => match &self.view {
                View::Ring(cal) => {
                    let bearings = self.ring_look(obs, cal)?;
                    self.conclude(&bearings, belief, out);
                }
                View::Pan(_) => {
                    out.actuators.push(ActuatorCommand::PanTo {
                        sensor: self.camera.clone(),
                        pan_rad: -PI,
                    });
                    self.state = State::Aim;
                }
            },
            State::Aim => {
                if self.pan_rad(obs)? <= RIGHT_STOP {
                    let rate = self.search.pan_rate_deg_s.to_radians();
                    out.actuators.push(self.pan_at(rate));
                    self.state = State::Sweep(vec![Track::default(); self.marks.len()]);
                    return self.run(obs, belief, out);
                }
                self.state = State::Aim;
            }
            State::Sweep(mut tracks) => {
                let View::Pan(cal) = &self.view else {
                    unreachable!("only a pan camera sweeps")
                };
                let at = self.sweep_frame(&mut tracks, obs, cal)?;
                if tracks.iter().all(Track::complete) || at >= -RIGHT_STOP {
                    out.actuators.push(self.pan_at(0.0));
                    let bearings: Vec<Option<f64>> = tracks.iter().map(Track::bearing).collect();
                    self.conclude(&bearings, belief, out);
                } else {
                    self.state = State::Sweep(tracks);
                }
            }
            State::Move(target) => {
                let here = belief.odometry_pose.translation.vector;
                if (target.coords - here).norm() < 5.0 {
                    // Arrived: the search starts with the next cycle's frames.
                    self.state = State::Start;
                    return Ok(());
                }
                out.percepts.put(ObservationPoint(target));
                self.state = State::Move(target);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_move_is_square_to_the_gap_where_the_missing_mark_is() {
        // Marks found at -90 and 0 degrees: the gap is from 0 round to 270, its middle 135;
        // the move goes to its left, 225 = -135 degrees.
        let d = move_direction(&[Some(-PI / 2.0), Some(0.0), None]);
        assert!((d.to_degrees() + 135.0).abs() < 1e-9, "{}", d.to_degrees());
        assert_eq!(move_direction(&[None, None, None]), 0.0);
        // One mark: the gap is the whole circle from it.
        let d = move_direction(&[None, Some(0.5), None]);
        assert!((wrap(d - 0.5 - 1.5 * PI)).abs() < 1e-9);
    }

    #[test]
    fn a_late_frame_gets_the_pan_of_when_it_was_taken() {
        let mut h = PanHistory::default();
        assert_eq!(h.at(0.0), None);
        for k in 0..5 {
            h.record(0.04 * f64::from(k), 0.1 * f64::from(k));
        }
        // 30 ms before the last reading (0.16 s, 0.4 rad): 0.13 s, 0.325 rad.
        assert!((h.at(0.13).unwrap() - 0.325).abs() < 1e-12);
        assert_eq!(h.at(1.0), Some(0.4));
        assert_eq!(h.at(-1.0), Some(0.0));
        // Time going back (a new run of the stage) starts the history again.
        h.record(0.0, 2.0);
        assert_eq!(h.at(0.13), Some(2.0));
    }

    #[test]
    fn a_track_averages_its_bearings_across_the_half_turn() {
        let t = Track {
            bearings: vec![PI - 0.01, -PI + 0.03],
            visible: false,
        };
        assert!((wrap(t.bearing().unwrap() - (PI + 0.01))).abs() < 1e-12);
        assert!(t.complete());
    }
}
