//! Free space in the floor region (Sect. 3.1 of the corner paper): the polar template on the
//! floor-colour mask, eqs. (5)-(7).

use super::stage::{
    Belief, CameraNeed, Perceived, PoseHistory, Stage, StageEntry, calibration, vision_camera,
    vision_settings,
};
use crate::RobotError;
use crate::boundary::Observation;
use crate::config::RobotConfig;
use crate::estimates::NotFound;
use crate::percept::Percept;
use image::RgbaImage;
use nalgebra::Isometry2;
use omniloop_problem::{Problem, Problems};
use omniloop_vision::FreeSpace;
use omniloop_vision::freespace::PolarTemplate;
use omniloop_vision::image_centre::dark_disc_centre;
use omniloop_vision::{FreeSpaceConfig, FreeSpaceDetector, RadialCalibration};

/// Free space around the robot (eqs. (5)-(7)). The estimates record writes it itself, as
/// `free_mm` beside the true free distances (`null` in a cycle without it), so it gives no
/// entry of its own.
impl Percept for FreeSpace {}

/// The stage's name, in the estimates record and the registry.
pub const NAME: &str = "freespace";

/// The registry's entry.
pub const ENTRY: StageEntry = StageEntry {
    name: NAME,
    summary: "free space in the floor region by the polar template, eqs. (5)-(7) (Sect. 3.1 of \
              the corner paper)",
    pose_source: None,
    table: None,
    vision_table: Some(TABLE),
    check_vision: |v| v.tables.check("vision", TABLE, check_values),
    asked: |_| false,
    camera: CameraNeed::MirrorFloor,
    world: &[],
    check,
    build: |c| {
        let camera = vision_camera(c, "free space")?;
        let cal = calibration(c, camera)?;
        let config = vision_settings(c, TABLE)?;
        Ok(Box::new(FreeSpaceStage::new(camera, config, cal)?))
    },
};

/// The stage's settings table, `[vision.freespace]`.
const TABLE: &str = "freespace";

/// The polar template on vision's camera's calibration, when the settings are good and the
/// calibration known.
fn check(c: &RobotConfig) -> Vec<Problem> {
    let cal = c.vision_camera().and_then(|cam| c.calibration(cam));
    let fs = c.vision.table::<FreeSpaceConfig>(TABLE);
    let (Some(cal), Ok(fs)) = (cal, fs) else {
        return Vec::new();
    };
    if !check_vision_values(&fs).is_empty() {
        return Vec::new();
    }
    match PolarTemplate::new(&fs, cal) {
        Ok(_) => Vec::new(),
        Err(e) => vec![Problem::new("vision.freespace", e.to_string())],
    }
}

/// `[vision.freespace]`'s values, each problem naming its field.
fn check_vision_values(fs: &FreeSpaceConfig) -> Vec<Problem> {
    let mut p = Problems::under("vision.freespace");
    check_values(fs, &mut p);
    p.into_vec()
}

/// `[vision.freespace]`'s values.
fn check_values(fs: &FreeSpaceConfig, p: &mut Problems) {
    if fs.directions < 4 {
        p.fail(
            "directions",
            format!("must be >= 4 (got {})", fs.directions),
        );
    }
    if fs.rings < 1 {
        p.fail("rings", "must be >= 1");
    }
    p.positive("inner_mm", fs.inner_mm);
    if fs.outer_mm.is_nan() || fs.outer_mm <= fs.inner_mm {
        let got = format!(
            "must exceed inner_mm = {} (got {})",
            fs.inner_mm, fs.outer_mm
        );
        p.fail("outer_mm", got);
    }
    if fs.r_th.is_nan() || fs.r_th <= 0.0 || fs.r_th > 1.0 {
        p.fail("r_th", format!("must lie in (0, 1] (got {})", fs.r_th));
    }
    if !fs.ring_edges_mm.is_empty() && !fs.ring_edges_px.is_empty() {
        p.fail(
            "ring_edges_px",
            "give ring_edges_mm or ring_edges_px, not both",
        );
    }
    for (key, edges) in [
        ("ring_edges_mm", &fs.ring_edges_mm),
        ("ring_edges_px", &fs.ring_edges_px),
    ] {
        if !edges.is_empty() && edges.len() != fs.rings + 1 {
            let n = edges.len();
            p.fail(
                key,
                format!("needs rings + 1 = {} values (got {n})", fs.rings + 1),
            );
        }
    }
    for k in 0..3 {
        if fs.floor.rgb_min[k] > fs.floor.rgb_max[k] {
            let (lo, hi) = (fs.floor.rgb_min[k], fs.floor.rgb_max[k]);
            p.fail(
                "floor.rgb_min",
                format!("channel {k}: {lo} exceeds rgb_max {hi}"),
            );
        }
    }
}

/// Detects free space in every frame of one mirror camera. A frame taken before now (a
/// camera with latency) or a cycle without a frame (a lost one) gives the last free space
/// moved to where odometry says the robot is now ([`omniloop_vision::FreeSpace::moved`]), up
/// to [`MAX_AGE_S`] after its frame was taken.
pub struct FreeSpaceStage {
    camera: String,
    detector: FreeSpaceDetector,
    /// The camera's calibration, its principal point the nominal one.
    cal: RadialCalibration,
    /// Whether the image's centre was checked (on the first frame).
    centred: bool,
    /// The last free space and the odometry pose when its frame was taken.
    last: Option<(FreeSpace, Isometry2<f64>, f64)>,
    /// `(t_s, odometry pose)` at the start of recent cycles.
    history: PoseHistory,
}

/// The oldest free space the stage gives (s after its frame was taken); older, none.
pub const MAX_AGE_S: f64 = 0.5;

impl FreeSpaceStage {
    /// A stage for `camera`, calibrated by `cal`.
    pub fn new(
        camera: &str,
        config: FreeSpaceConfig,
        cal: &RadialCalibration,
    ) -> Result<Self, RobotError> {
        Ok(Self {
            camera: camera.to_string(),
            detector: FreeSpaceDetector::new(config, cal)?,
            cal: cal.clone(),
            centred: false,
            last: None,
            history: PoseHistory::default(),
        })
    }

    /// Lays the template about the robot's own image when the first frame shows it more than
    /// `recentre_px` off the calibration's principal point (a mirror off its place).
    fn recentre(&mut self, img: &RgbaImage) -> Result<(), RobotError> {
        self.centred = true;
        let limit = self.detector.config().recentre_px;
        let inner = self.detector.template().edges_px().first().copied();
        let (Some(inner), true) = (inner, limit > 0.0) else {
            return Ok(());
        };
        let pp = self.cal.principal_point_px;
        let min_pixels = (0.25 * std::f64::consts::PI * inner * inner) as usize;
        let Some(c) = dark_disc_centre(img, pp, inner, DARK_LEVEL, min_pixels) else {
            return Ok(());
        };
        let moved = (c[0] - pp[0]).hypot(c[1] - pp[1]);
        if moved > limit {
            let mut cal = self.cal.clone();
            cal.principal_point_px = c;
            self.detector = FreeSpaceDetector::new(self.detector.config().clone(), &cal)?;
        }
        Ok(())
    }
}

impl FreeSpaceStage {
    /// The free space of `img`, a frame of this stage's camera taken now, as the stage gives it
    /// within a cycle (on the first frame, the template is laid about the robot's own image
    /// first): what a robot's software outside omniloop's loop (a ROS 2 node) gets from a frame.
    pub fn detect_frame(&mut self, img: &RgbaImage) -> Result<FreeSpace, RobotError> {
        if !self.centred {
            self.recentre(img)?;
        }
        Ok(self.detector.detect(img)?)
    }

    /// The camera whose frames it reads.
    pub fn camera(&self) -> &str {
        &self.camera
    }
}

/// The brightest channel of the robot's own dark image (its top and the camera seen in the
/// mirror).
const DARK_LEVEL: u8 = 64;

impl Stage for FreeSpaceStage {
    fn name(&self) -> &'static str {
        NAME
    }

    fn cameras(&self) -> Vec<&str> {
        vec![&self.camera]
    }

    fn runs_without_frames(&self) -> bool {
        true
    }

    fn carried(&mut self) {
        self.last = None;
        self.history.clear();
    }

    fn run(
        &mut self,
        obs: &Observation<'_>,
        belief: &Belief,
        out: &mut Perceived,
    ) -> Result<(), RobotError> {
        let now = belief.odometry_pose;
        self.history.push(obs.t_s, now, 2.0 * MAX_AGE_S);
        if let Some(frame) = obs.frame(&self.camera).filter(|_| !self.centred) {
            self.recentre(frame.image)?;
        }
        match obs.frames.iter().find(|f| f.sensor == self.camera) {
            Some(frame) if (obs.t_s - frame.t_s).abs() < 1e-9 => {
                // Taken now: as it is.
                let fs = self.detect_frame(frame.image)?;
                self.last = Some((fs.clone(), now, frame.t_s));
                out.percepts.put(fs);
                return Ok(());
            }
            Some(frame) => {
                let taken = self.history.at(frame.t_s).unwrap_or(now);
                self.last = Some((self.detector.detect(frame.image)?, taken, frame.t_s));
            }
            None => out.not_found.push(NotFound {
                source: self.name(),
                reason: format!("no frame of camera {:?} this cycle", self.camera),
            }),
        }
        if let Some((fs, taken, t)) = &self.last
            && obs.t_s - t <= MAX_AGE_S
        {
            out.percepts.put(fs.moved(&(taken.inverse() * now)));
        }
        Ok(())
    }
}
