//! Every cycle of a run on Foxglove channels, with Foxglove's well-known schemas; a sink (an
//! MCAP file, a live WebSocket server) on the same context gets them. Message times are the
//! simulation's, from 0 at the run's start.

use super::scene::{free_space, moving, path, pose_in, stamp, transform, world_scene};
use crate::run::observer::CycleView;
use foxglove::messages::{CompressedImage, FrameTransform, PoseInFrame, RawImage, SceneUpdate};
use foxglove::{Channel, ChannelBuilder, Context, PartialMetadata, RawChannel};
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_robot::Frame;
use omniloop_sim::World;
use omniloop_sim::render::TruthFrame;
use omniloop_vision::FreeSpace;
use std::collections::BTreeMap;
use std::sync::Arc;

/// The channels of a run: for the one robot `/camera/NAME`, `/truth/pose`, `/truth/tf`,
/// `/estimate/pose`, `/estimate/tf`, `/estimate/error`, `/estimate/free_space`,
/// `/estimate/path`, `/command`, `/estimate/record`, and with the truth traced
/// `/truth/camera/NAME/depth` (16UC1, mm) and `/truth/camera/NAME/labels` (rgb8, the legend's
/// colours) with the legend on `/truth/legend` (a team's robots each under its name:
/// `/ROBOT/camera/NAME`, `/ROBOT/truth/pose`, ..., in frames `ROBOT/truth/base_link`,
/// `ROBOT/estimate/base_link`); and `/world`, `/summary`, and where things move that have no
/// software (the ball, the scripted robots) `/truth/moving`.
pub struct Recorder {
    ctx: Arc<Context>,
    robots: Vec<RobotChannels>,
    world: Arc<Channel<SceneUpdate>>,
    /// The ball and the scripted robots, made at their first cycle.
    moving: Option<Channel<SceneUpdate>>,
    summary: Arc<RawChannel>,
    /// Why a message could not be made, the first time (a frame that did not encode).
    pub problem: Option<String>,
}

/// The channels of one robot.
struct RobotChannels {
    /// The topics' and frames' prefix: empty for the one robot, `ROBOT/` in a team.
    prefix: String,
    cameras: BTreeMap<String, Channel<CompressedImage>>,
    /// Each camera's truth channels: depth and labels.
    truth_images: BTreeMap<String, [Channel<RawImage>; 2]>,
    /// The labels' legend, once.
    legend: Option<Arc<RawChannel>>,
    truth_pose: Channel<PoseInFrame>,
    truth_tf: Channel<FrameTransform>,
    estimate_pose: Channel<PoseInFrame>,
    estimate_tf: Channel<FrameTransform>,
    free_space: Channel<SceneUpdate>,
    path: Channel<SceneUpdate>,
    command: Arc<RawChannel>,
    error: Arc<RawChannel>,
    record: Arc<RawChannel>,
}

/// The frames of the tree: the world, the true robot, the robot as it believes it is.
pub const WORLD: &str = "world";
/// The true robot's frame (a team's robot's: `ROBOT/truth/base_link`).
pub const TRUTH: &str = "truth/base_link";
/// The estimated robot's frame (a team's robot's: `ROBOT/estimate/base_link`).
pub const ESTIMATE: &str = "estimate/base_link";

/// A robot's cameras as the log names them: its name in a team (`None` for the one robot) and
/// its cameras.
#[derive(Debug, Clone)]
pub struct RobotCameras {
    /// The robot's name in a team; `None` for the one robot of a scenario.
    pub robot: Option<String>,
    /// Its cameras' names.
    pub sensors: Vec<String>,
}

/// The channel of a camera's frames, `/PREFIXcamera/NAME`.
fn camera_channel(ctx: &Arc<Context>, prefix: &str, sensor: &str) -> Channel<CompressedImage> {
    ChannelBuilder::new(format!("/{prefix}camera/{sensor}"))
        .context(ctx)
        .build()
}

/// A channel of JSON messages on `topic`.
fn json(ctx: &Arc<Context>, topic: &str) -> Result<Arc<RawChannel>, foxglove::FoxgloveError> {
    ChannelBuilder::new(topic)
        .context(ctx)
        .message_encoding("json")
        .build_raw()
}

impl RobotChannels {
    /// One robot's channels on `ctx`.
    fn new(ctx: &Arc<Context>, robot: &RobotCameras) -> Result<Self, foxglove::FoxgloveError> {
        let prefix = robot
            .robot
            .as_ref()
            .map_or(String::new(), |r| format!("{r}/"));
        let topic = |t: &str| format!("/{prefix}{t}");
        let typed = |t: &str| ChannelBuilder::new(topic(t)).context(ctx);
        Ok(Self {
            cameras: robot
                .sensors
                .iter()
                .map(|s| (s.clone(), camera_channel(ctx, &prefix, s)))
                .collect(),
            truth_images: BTreeMap::new(),
            legend: None,
            truth_pose: typed("truth/pose").build(),
            truth_tf: typed("truth/tf").build(),
            estimate_pose: typed("estimate/pose").build(),
            estimate_tf: typed("estimate/tf").build(),
            free_space: typed("estimate/free_space").build(),
            path: typed("estimate/path").build(),
            command: json(ctx, &topic("command"))?,
            error: json(ctx, &topic("estimate/error"))?,
            record: json(ctx, &topic("estimate/record"))?,
            prefix,
        })
    }
}

impl Recorder {
    /// The channels, on `ctx`, for `robots` with a camera channel for each of their cameras
    /// (another camera's is made at its first frame).
    pub fn new(
        ctx: &Arc<Context>,
        robots: &[RobotCameras],
    ) -> Result<Self, foxglove::FoxgloveError> {
        Ok(Self {
            ctx: ctx.clone(),
            robots: robots
                .iter()
                .map(|r| RobotChannels::new(ctx, r))
                .collect::<Result<_, _>>()?,
            world: Arc::new(ChannelBuilder::new("/world").context(ctx).build()),
            moving: None,
            summary: json(ctx, "/summary")?,
            problem: None,
        })
    }

    /// The run's summary on `/summary`, at `t_s`, without its wall-clock figures
    /// (`wall_time_s`, `cycles_per_s`: `summary.json` has them), so that the same scenario and
    /// seed give the same file.
    pub fn summary(&self, t_s: f64, summary: &crate::run::Summary) {
        let mut json = serde_json::to_value(summary).unwrap_or_default();
        if let Some(m) = json.as_object_mut() {
            m.remove("wall_time_s");
            m.remove("cycles_per_s");
        }
        self.summary
            .log_with_meta(json.to_string().as_bytes(), at(t_s));
    }

    /// A camera's frame as a PNG on robot `k`'s `/camera/NAME`: RGB, stored without deflate
    /// or filters (the sensor noise leaves a quarter of it to compress, for most of a core;
    /// see `docs/viewing.md`).
    fn frame(&mut self, k: usize, t_s: f64, f: &OwnedFrame) {
        let ctx = &self.ctx;
        let robot = &mut self.robots[k];
        let prefix = robot.prefix.clone();
        let channel = robot
            .cameras
            .entry(f.sensor.clone())
            .or_insert_with(|| camera_channel(ctx, &prefix, &f.sensor));
        let mut png = Vec::new();
        let encoder = image::codecs::png::PngEncoder::new_with_quality(
            &mut png,
            image::codecs::png::CompressionType::Uncompressed,
            image::codecs::png::FilterType::NoFilter,
        );
        let rgb: image::RgbImage = image::buffer::ConvertBuffer::convert(&f.image);
        if let Err(e) = rgb.write_with_encoder(encoder) {
            self.problem
                .get_or_insert(format!("camera {prefix}{}: {e}", f.sensor));
            return;
        }
        channel.log_with_meta(
            &CompressedImage {
                timestamp: Some(stamp(f.t_s)),
                frame_id: format!("{prefix}camera/{}", f.sensor),
                data: png.into(),
                format: "png".into(),
            },
            at(t_s),
        );
    }

    /// A frame's truth on robot `k`'s `/truth/camera/NAME/depth` and `/labels` (the legend on
    /// `/truth/legend` with the first).
    fn truth(&mut self, k: usize, t_s: f64, sensor: &str, truth: &TruthFrame) {
        let ctx = &self.ctx;
        let robot = &mut self.robots[k];
        let prefix = robot.prefix.clone();
        if robot.legend.is_none() {
            let legend = json(ctx, &format!("/{prefix}truth/legend")).ok();
            let entries = serde_json::to_string(&truth.legend.entries()).unwrap_or_default();
            if let Some(c) = &legend {
                c.log_with_meta(entries.as_bytes(), at(t_s));
            }
            robot.legend = legend;
        }
        let channels = robot
            .truth_images
            .entry(sensor.to_string())
            .or_insert_with(|| {
                let topic = |kind: &str| format!("/{prefix}truth/camera/{sensor}/{kind}");
                let channel = |kind: &str| ChannelBuilder::new(topic(kind)).context(ctx).build();
                [channel("depth"), channel("labels")]
            });
        let depth: Vec<u8> = (truth.depth_mm.iter())
            .flat_map(|&d| crate::run::truth_files::depth_level(d).to_le_bytes())
            .collect();
        let palette = truth.legend.entries();
        let colours: Vec<u8> = (truth.labels.iter())
            .flat_map(|&l| palette.get(l as usize).map_or([0; 3], |e| e.rgb))
            .collect();
        let image = |encoding: &str, bytes: usize, data: Vec<u8>| RawImage {
            timestamp: Some(stamp(t_s)),
            frame_id: format!("{prefix}camera/{sensor}"),
            width: truth.width,
            height: truth.height,
            encoding: encoding.into(),
            step: truth.width * bytes as u32,
            data: data.into(),
        };
        channels[0].log_with_meta(&image("16UC1", 2, depth), at(t_s));
        channels[1].log_with_meta(&image("rgb8", 3, colours), at(t_s));
    }

    /// The world's static scene on `/world`.
    pub fn world(&self, scene: &SceneUpdate) {
        self.world.log_with_meta(scene, at(0.0));
    }

    /// The `/world` channel.
    pub fn world_channel(&self) -> Arc<Channel<SceneUpdate>> {
        self.world.clone()
    }

    /// One cycle on every channel.
    pub fn cycle(&mut self, c: &Cycle) {
        for (k, robot) in c.robots.iter().enumerate().take(self.robots.len()) {
            for f in &robot.frames {
                self.frame(k, robot.row.t_s, f);
            }
            for (sensor, truth) in &robot.truth {
                self.truth(k, robot.row.t_s, sensor, truth);
            }
            self.robots[k].log(robot);
        }
        if c.ball.is_some() || !c.others.is_empty() {
            let t = c.robots.first().map_or(0.0, |r| r.row.t_s);
            let ctx = &self.ctx;
            let channel = (self.moving)
                .get_or_insert_with(|| ChannelBuilder::new("/truth/moving").context(ctx).build());
            let ball = c.ball.as_ref().map(|(row, spec)| (row, spec));
            channel.log_with_meta(&moving(t, ball, &c.others), at(t));
        }
    }
}

impl RobotChannels {
    /// One robot's cycle on its channels (its frames aside).
    fn log(&self, c: &RobotCycleOwned) {
        let r = &c.row;
        let t = r.t_s;
        let (truth_frame, estimate_frame) = (
            format!("{}{TRUTH}", self.prefix),
            format!("{}{ESTIMATE}", self.prefix),
        );
        let truth = Isometry2::new(Vector2::new(r.x_mm, r.y_mm), r.theta_rad);
        self.truth_pose
            .log_with_meta(&pose_in(t, WORLD, &truth), at(t));
        self.truth_tf
            .log_with_meta(&transform(t, WORLD, &truth_frame, &truth), at(t));
        if let Some(est) = &c.estimate {
            self.estimate_pose
                .log_with_meta(&pose_in(t, WORLD, est), at(t));
            self.estimate_tf
                .log_with_meta(&transform(t, WORLD, &estimate_frame, est), at(t));
            let off = est.inverse() * truth;
            let error = serde_json::json!({
                "t_s": t,
                "position_mm": (est.translation.vector - truth.translation.vector).norm(),
                "heading_deg": off.rotation.angle().to_degrees(),
            });
            self.error
                .log_with_meta(error.to_string().as_bytes(), at(t));
        }
        if let Some(fs) = &c.freespace {
            self.free_space
                .log_with_meta(&free_space(t, &truth_frame, fs), at(t));
        }
        if let Some(p) = &c.path {
            self.path.log_with_meta(&path(t, p), at(t));
        }
        let command = serde_json::json!({
            "t_s": t,
            "vx_mm_s": r.cmd_vx_mm_s,
            "vy_mm_s": r.cmd_vy_mm_s,
        });
        self.command
            .log_with_meta(command.to_string().as_bytes(), at(t));
        self.record.log_with_meta(c.record.as_bytes(), at(t));
    }
}

/// A camera frame the recorder owns.
pub struct OwnedFrame {
    /// The camera.
    pub sensor: String,
    /// When it was taken, s.
    pub t_s: f64,
    /// The image.
    pub image: image::RgbaImage,
}

/// One cycle as the recorder keeps it (the loop goes on while it is written): every robot's,
/// the ball's and the scripted robots'.
pub struct Cycle {
    /// Each robot's part, in the robots' order.
    pub robots: Vec<RobotCycleOwned>,
    /// The ball and its description, when there is one.
    pub ball: Option<(crate::run::BallRow, omniloop_sim::BallSpec)>,
    /// The scripted robots' bodies.
    pub others: Vec<omniloop_sim::Solid>,
}

/// One robot's part of a cycle as the recorder keeps it.
pub struct RobotCycleOwned {
    /// Its row of `trajectory.csv`.
    pub row: crate::run::TrajectoryRow,
    /// The frames the software got.
    pub frames: Vec<OwnedFrame>,
    /// With the truth traced: each frame's truth, by camera.
    pub truth: Vec<(String, TruthFrame)>,
    /// The pose the robot believed.
    pub estimate: Option<Isometry2<f64>>,
    /// The free space it saw.
    pub freespace: Option<omniloop_vision::FreeSpace>,
    /// Its planner's path, world mm.
    pub path: Option<Vec<Point2<f64>>>,
    /// Its line of `estimates.jsonl`.
    pub record: String,
}

impl Cycle {
    /// What the recorder keeps of a cycle.
    pub fn of(v: &CycleView<'_>) -> Self {
        let robots = v
            .robots
            .iter()
            .map(|r| RobotCycleOwned {
                row: *r.row,
                frames: r
                    .frames
                    .iter()
                    .map(|f: &Frame<'_>| OwnedFrame {
                        sensor: f.sensor.to_string(),
                        t_s: f.t_s,
                        image: f.image.clone(),
                    })
                    .collect(),
                truth: (r.truth.iter())
                    .map(|(s, t)| (s.to_string(), (*t).clone()))
                    .collect(),
                estimate: r.estimates.pose,
                freespace: r.estimates.percept::<FreeSpace>().cloned(),
                path: r.estimates.navigation.as_ref().map(|n| n.path_mm.clone()),
                record: crate::run::record::estimates_line(r.row, r.estimates, r.floor),
            })
            .collect();
        Self {
            robots,
            ball: v.ball.map(|(row, spec)| (row.clone(), spec.clone())),
            others: v.others.to_vec(),
        }
    }
}

/// The world's static scene: its solids and, under them, its floor.
pub fn world_update(world: &World) -> SceneUpdate {
    let solids = world.solids();
    let floor = bounds(solids).map(|b| (b, world.layout().floor_rgb.0));
    world_scene(solids, floor)
}

/// Message metadata: logged at simulation time `t_s`.
fn at(t_s: f64) -> PartialMetadata {
    PartialMetadata::with_log_time(stamp(t_s).total_nanos())
}

/// The bounding box `[x0, y0, x1, y1]` (mm) of the solids' footprints, with a margin.
fn bounds(solids: &[omniloop_sim::Solid]) -> Option<[f64; 4]> {
    let mut pts: Vec<Point2<f64>> = Vec::new();
    for s in solids {
        match &s.shape {
            omniloop_sim::SolidShape::Box {
                center_mm,
                half_extents_mm,
                ..
            } => {
                let r = half_extents_mm.norm();
                pts.extend([
                    center_mm - Vector2::new(r, r),
                    center_mm + Vector2::new(r, r),
                ]);
            }
            omniloop_sim::SolidShape::Cylinder {
                center_mm,
                radius_mm,
            } => pts.extend([
                center_mm - Vector2::new(*radius_mm, *radius_mm),
                center_mm + Vector2::new(*radius_mm, *radius_mm),
            ]),
            omniloop_sim::SolidShape::Quad { corners_mm } => pts.extend(corners_mm.iter()),
        }
    }
    let first = pts.first()?;
    let init = [first.x, first.y, first.x, first.y];
    let b = pts.iter().fold(init, |b, p| {
        [b[0].min(p.x), b[1].min(p.y), b[2].max(p.x), b[3].max(p.y)]
    });
    Some([b[0] - 200.0, b[1] - 200.0, b[2] + 200.0, b[3] + 200.0])
}
