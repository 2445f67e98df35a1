//! The overhead vision the league gives every team, as ssl-vision sends it: detection frames
//! of the robots and the ball, one a camera, each camera seeing its part of the field grown by
//! an overlap; geometry packets with the field and the cameras. With realism on, as ER-Force's
//! simulator's "realistic" preset describes it: Gaussian noise on positions and orientations,
//! a delay from capture to sending, detections missed at random, and a ball a camera cannot
//! see past a robot. Every draw comes from the scenario's seed.

use super::wire::vision::{
    DetectionBall, DetectionFrame, DetectionRobot, FieldCircularArc, FieldLineSegment,
    GeometryCameraCalibration, GeometryData, GeometryFieldSize, Vector2f,
};
use crate::scenario::ssl::{SslRealism, SslVision, TeamColor};
use nalgebra::{Point2, Point3};
use omniloop_sim::FieldSpec;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, Normal};
use std::collections::VecDeque;

/// A camera's focal length in the geometry packets and detections, px.
const FOCAL_PX: f64 = 600.0;
/// A camera's image in the geometry packets, px.
const IMAGE_PX: [u32; 2] = [780, 580];

/// A robot as the overhead cameras see it (truth, from the simulator).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeenRobot {
    /// Its team.
    pub team: TeamColor,
    /// Its id.
    pub id: u32,
    /// Position, mm.
    pub at_mm: Point2<f64>,
    /// Heading, rad.
    pub heading_rad: f64,
    /// Body radius, mm.
    pub radius_mm: f64,
    /// Height, mm.
    pub height_mm: f64,
}

/// The world at a capture, as the overhead cameras see it.
#[derive(Debug, Clone, PartialEq)]
pub struct Capture {
    /// Simulated time of the capture, s.
    pub t_s: f64,
    /// The robots on the field.
    pub robots: Vec<SeenRobot>,
    /// The ball's centre, mm (none without a ball).
    pub ball_mm: Option<Point3<f64>>,
}

/// One overhead camera: its part of the field (grown by the overlap) and where it hangs.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Camera {
    min_mm: Point2<f64>,
    max_mm: Point2<f64>,
    at_mm: Point3<f64>,
}

impl Camera {
    fn sees(&self, p: Point2<f64>) -> bool {
        (self.min_mm.x..=self.max_mm.x).contains(&p.x)
            && (self.min_mm.y..=self.max_mm.y).contains(&p.y)
    }

    /// A point's pixel in this camera's image (a pinhole looking straight down).
    fn pixel(&self, p: Point3<f64>) -> (f32, f32) {
        let depth = (self.at_mm.z - p.z).max(1.0);
        let u = f64::from(IMAGE_PX[0]) / 2.0 + FOCAL_PX * (p.x - self.at_mm.x) / depth;
        let v = f64::from(IMAGE_PX[1]) / 2.0 - FOCAL_PX * (p.y - self.at_mm.y) / depth;
        (u as f32, v as f32)
    }

    /// Whether a robot stands between this camera and the ball: the ray from the camera to
    /// the ball's centre passes through a robot's cylinder.
    fn hidden(&self, ball: Point3<f64>, robots: &[SeenRobot]) -> bool {
        robots.iter().any(|r| {
            if ball.z >= r.height_mm {
                return false;
            }
            // The ray enters the robot's height at `top`, reaching the ball below it.
            let s = (self.at_mm.z - r.height_mm) / (self.at_mm.z - ball.z);
            let top = self.at_mm.xy() + s * (ball.xy() - self.at_mm.xy());
            segment_distance(r.at_mm, top, ball.xy()) < r.radius_mm
        })
    }
}

/// Distance from `p` to the segment `a`–`b`.
fn segment_distance(p: Point2<f64>, a: Point2<f64>, b: Point2<f64>) -> f64 {
    let ab = b - a;
    let t = if ab.norm_squared() > 0.0 {
        ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + t * ab)).norm()
}

/// The overhead vision: its cameras, its realism and its queue of frames not yet sent.
pub struct OverheadVision {
    cameras: Vec<Camera>,
    realism: Option<SslRealism>,
    rng: StdRng,
    frame_number: u32,
    /// Frames captured, waiting for their sending time (s).
    queue: VecDeque<(f64, DetectionFrame)>,
    geometry: GeometryData,
}

impl OverheadVision {
    /// The cameras of `spec` over `field`, their draws seeded by `seed`.
    pub fn new(spec: &SslVision, field: &FieldSpec, ball_radius_mm: f64, seed: u64) -> Self {
        let cameras = cameras(spec, field);
        let geometry = geometry(field, &cameras, ball_radius_mm);
        Self {
            cameras,
            realism: spec.realism.enabled.then(|| spec.realism.clone()),
            rng: StdRng::seed_from_u64(seed ^ 0x55C1_0000_5EE5_0001),
            frame_number: 0,
            queue: VecDeque::new(),
            geometry,
        }
    }

    /// The geometry packet's contents.
    pub fn geometry(&self) -> &GeometryData {
        &self.geometry
    }

    /// How many cameras there are.
    pub fn camera_count(&self) -> usize {
        self.cameras.len()
    }

    /// Captures the world now: a frame from each camera, queued until its sending time.
    pub fn capture(&mut self, c: &Capture) {
        let delay = self.realism.as_ref().map_or(0.0, |r| r.delay_s);
        for k in 0..self.cameras.len() {
            let frame = self.frame(k, c, delay);
            self.queue.push_back((c.t_s + delay, frame));
        }
        self.frame_number = self.frame_number.wrapping_add(1);
    }

    /// The frames due by `now_s`, in capture order.
    pub fn due(&mut self, now_s: f64) -> Vec<DetectionFrame> {
        let mut out = Vec::new();
        while let Some((t, _)) = self.queue.front() {
            if *t > now_s + 1e-9 {
                break;
            }
            if let Some((_, f)) = self.queue.pop_front() {
                out.push(f);
            }
        }
        out
    }

    fn frame(&mut self, k: usize, c: &Capture, delay_s: f64) -> DetectionFrame {
        let cam = self.cameras[k];
        let mut frame = DetectionFrame {
            frame_number: self.frame_number,
            t_capture: c.t_s,
            t_sent: c.t_s + delay_s,
            camera_id: k as u32,
            balls: Vec::new(),
            robots_yellow: Vec::new(),
            robots_blue: Vec::new(),
            t_capture_camera: Some(c.t_s),
        };
        for r in &c.robots {
            if !cam.sees(r.at_mm) || self.missed(|q| q.robot_miss) {
                continue;
            }
            let d = self.robot(&cam, r);
            match r.team {
                TeamColor::Blue => frame.robots_blue.push(d),
                TeamColor::Yellow => frame.robots_yellow.push(d),
            }
        }
        if let Some(b) = c.ball_mm {
            let occluded =
                self.realism.as_ref().is_some_and(|q| q.occlusion) && cam.hidden(b, &c.robots);
            if cam.sees(b.xy()) && !occluded && !self.missed(|q| q.ball_miss) {
                frame.balls.push(self.ball(&cam, b));
            }
        }
        frame
    }

    fn missed(&mut self, chance: impl Fn(&SslRealism) -> f64) -> bool {
        match &self.realism {
            Some(q) => {
                let p = chance(q);
                p > 0.0 && self.rng.random_bool(p.min(1.0))
            }
            None => false,
        }
    }

    fn noise(&mut self, sigma: impl Fn(&SslRealism) -> f64) -> f64 {
        let Some(s) = self.realism.as_ref().map(sigma) else {
            return 0.0;
        };
        match Normal::new(0.0, s) {
            Ok(n) if s > 0.0 => n.sample(&mut self.rng),
            _ => 0.0,
        }
    }

    fn robot(&mut self, cam: &Camera, r: &SeenRobot) -> DetectionRobot {
        let x = r.at_mm.x + self.noise(|q| q.robot_noise_mm);
        let y = r.at_mm.y + self.noise(|q| q.robot_noise_mm);
        let heading = r.heading_rad + self.noise(|q| q.robot_noise_rad);
        let (px, py) = cam.pixel(Point3::new(r.at_mm.x, r.at_mm.y, r.height_mm));
        DetectionRobot {
            confidence: 1.0,
            robot_id: Some(r.id),
            x: x as f32,
            y: y as f32,
            orientation: Some(wrap(heading) as f32),
            pixel_x: px,
            pixel_y: py,
            height: Some(r.height_mm as f32),
        }
    }

    fn ball(&mut self, cam: &Camera, b: Point3<f64>) -> DetectionBall {
        let x = b.x + self.noise(|q| q.ball_noise_mm);
        let y = b.y + self.noise(|q| q.ball_noise_mm);
        let (px, py) = cam.pixel(b);
        DetectionBall {
            confidence: 1.0,
            area: Some(80),
            x: x as f32,
            y: y as f32,
            z: Some(b.z.max(0.0) as f32),
            pixel_x: px,
            pixel_y: py,
        }
    }
}

/// An angle in [-pi, pi).
fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

/// The grid of cameras over the floor (the field and its run-off), camera 0 at -x, -y.
fn cameras(spec: &SslVision, f: &FieldSpec) -> Vec<Camera> {
    let hx = f.half_length_mm + f.boundary_width_mm;
    let hy = f.half_width_mm + f.boundary_width_mm;
    let [nx, ny] = spec.cameras.map(f64::from);
    let (w, h) = (2.0 * hx / nx, 2.0 * hy / ny);
    let mut out = Vec::new();
    for j in 0..spec.cameras[1] {
        for i in 0..spec.cameras[0] {
            let x0 = -hx + f64::from(i) * w;
            let y0 = -hy + f64::from(j) * h;
            let edge = |v: f64, lo: bool| {
                let limit = if lo { -1e9 } else { 1e9 };
                // The outer edges see to the walls and beyond; inner ones overlap.
                if (lo && v <= -hx.max(hy) - 1.0) || (!lo && v >= hx.max(hy) + 1.0) {
                    limit
                } else if lo {
                    v - spec.overlap_mm
                } else {
                    v + spec.overlap_mm
                }
            };
            let min_x = if i == 0 { -1e9 } else { edge(x0, true) };
            let max_x = if i + 1 == spec.cameras[0] {
                1e9
            } else {
                edge(x0 + w, false)
            };
            let min_y = if j == 0 { -1e9 } else { edge(y0, true) };
            let max_y = if j + 1 == spec.cameras[1] {
                1e9
            } else {
                edge(y0 + h, false)
            };
            out.push(Camera {
                min_mm: Point2::new(min_x, min_y),
                max_mm: Point2::new(max_x, max_y),
                at_mm: Point3::new(x0 + w / 2.0, y0 + h / 2.0, spec.camera_height_mm),
            });
        }
    }
    out
}

fn v2(x: f64, y: f64) -> Vector2f {
    Vector2f {
        x: x as f32,
        y: y as f32,
    }
}

fn line(name: &str, a: (f64, f64), b: (f64, f64), t: f64) -> FieldLineSegment {
    FieldLineSegment {
        name: name.to_string(),
        p1: v2(a.0, a.1),
        p2: v2(b.0, b.1),
        thickness: t as f32,
        r#type: None,
    }
}

/// The field's lines as ssl-vision names them.
fn field_lines(f: &FieldSpec) -> Vec<FieldLineSegment> {
    let (l, w, t) = (f.half_length_mm, f.half_width_mm, f.line_width_mm);
    let (d, pw) = (f.defense_area_depth_mm, f.defense_area_width_mm / 2.0);
    let mut lines = vec![
        line("TopTouchLine", (-l, w), (l, w), t),
        line("BottomTouchLine", (-l, -w), (l, -w), t),
        line("LeftGoalLine", (-l, -w), (-l, w), t),
        line("RightGoalLine", (l, -w), (l, w), t),
        line("HalfwayLine", (0.0, -w), (0.0, w), t),
        line("CenterLine", (-l, 0.0), (l, 0.0), t),
    ];
    if d > 0.0 && pw > 0.0 {
        lines.extend([
            line("LeftPenaltyStretch", (-l + d, -pw), (-l + d, pw), t),
            line("RightPenaltyStretch", (l - d, -pw), (l - d, pw), t),
            line("LeftFieldLeftPenaltyStretch", (-l, pw), (-l + d, pw), t),
            line("LeftFieldRightPenaltyStretch", (-l, -pw), (-l + d, -pw), t),
            line("RightFieldLeftPenaltyStretch", (l, -pw), (l - d, -pw), t),
            line("RightFieldRightPenaltyStretch", (l, pw), (l - d, pw), t),
        ]);
    }
    lines
}

/// The geometry packet: the field's size and lines, and each camera's calibration (a camera
/// looking straight down from where it hangs).
fn geometry(f: &FieldSpec, cameras: &[Camera], ball_radius_mm: f64) -> GeometryData {
    let mm = |v: f64| v.round() as i32;
    let field = GeometryFieldSize {
        field_length: mm(2.0 * f.half_length_mm),
        field_width: mm(2.0 * f.half_width_mm),
        goal_width: mm(f.goal_width_mm),
        goal_depth: mm(f.goal_depth_mm),
        boundary_width: mm(f.boundary_width_mm),
        field_lines: field_lines(f),
        field_arcs: vec![FieldCircularArc {
            name: "CenterCircle".to_string(),
            center: v2(0.0, 0.0),
            radius: f.centre_circle_radius_mm as f32,
            a1: 0.0,
            a2: std::f32::consts::TAU,
            thickness: f.line_width_mm as f32,
            r#type: None,
        }],
        penalty_area_depth: Some(mm(f.defense_area_depth_mm)),
        penalty_area_width: Some(mm(f.defense_area_width_mm)),
        center_circle_radius: Some(mm(f.centre_circle_radius_mm)),
        line_thickness: Some(mm(f.line_width_mm)),
        goal_center_to_penalty_mark: None,
        goal_height: Some(mm(f.goal_wall_height_mm)),
        ball_radius: Some(ball_radius_mm as f32),
        max_robot_radius: Some(90.0),
        boundary_width_goal_line: None,
        goal_substitution_area_width: None,
    };
    let calib = cameras
        .iter()
        .enumerate()
        .map(|(k, c)| GeometryCameraCalibration {
            camera_id: k as u32,
            focal_length: FOCAL_PX as f32,
            principal_point_x: IMAGE_PX[0] as f32 / 2.0,
            principal_point_y: IMAGE_PX[1] as f32 / 2.0,
            distortion: 0.0,
            // Looking down: a half turn about the x axis (q0..q2 the vector part, q3 scalar).
            q0: 1.0,
            q1: 0.0,
            q2: 0.0,
            q3: 0.0,
            tx: -c.at_mm.x as f32,
            ty: c.at_mm.y as f32,
            tz: c.at_mm.z as f32,
            derived_camera_world_tx: Some(c.at_mm.x as f32),
            derived_camera_world_ty: Some(c.at_mm.y as f32),
            derived_camera_world_tz: Some(c.at_mm.z as f32),
            pixel_image_width: Some(IMAGE_PX[0]),
            pixel_image_height: Some(IMAGE_PX[1]),
        })
        .collect();
    GeometryData {
        field,
        calib,
        models: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use omniloop_sim::FieldPreset;

    fn robot(team: TeamColor, id: u32, x: f64, y: f64) -> SeenRobot {
        SeenRobot {
            team,
            id,
            at_mm: Point2::new(x, y),
            heading_rad: 0.5,
            radius_mm: 90.0,
            height_mm: 150.0,
        }
    }

    fn capture() -> Capture {
        Capture {
            t_s: 1.0,
            robots: vec![
                robot(TeamColor::Blue, 0, -2000.0, -1000.0),
                robot(TeamColor::Yellow, 3, 2000.0, 1000.0),
                robot(TeamColor::Blue, 1, 10.0, 20.0),
            ],
            ball_mm: Some(Point3::new(500.0, -400.0, 21.5)),
        }
    }

    #[test]
    fn each_camera_reports_its_part_and_the_overlap_reports_twice() {
        let mut v = OverheadVision::new(
            &SslVision::default(),
            &FieldPreset::DivisionB.spec(),
            21.5,
            1,
        );
        v.capture(&capture());
        let frames = v.due(1.0);
        assert_eq!(frames.len(), 4);
        let blue: usize = frames.iter().map(|f| f.robots_blue.len()).sum();
        // Robot 0 in one camera's part, robot 1 by the centre in all four.
        assert_eq!(blue, 5);
        assert_eq!(frames[0].robots_blue[0].x, -2000.0);
        let balls: usize = frames.iter().map(|f| f.balls.len()).sum();
        assert_eq!(balls, 1);
    }

    #[test]
    fn realism_delays_noises_and_hides_the_ball_behind_a_robot() {
        let mut spec = SslVision::default();
        spec.realism.enabled = true;
        spec.realism.ball_miss = 0.0;
        spec.realism.robot_miss = 0.0;
        let mut v = OverheadVision::new(&spec, &FieldPreset::DivisionB.spec(), 21.5, 7);
        let mut c = capture();
        v.capture(&c);
        assert!(v.due(1.0).is_empty(), "sent before the delay");
        let frames = v.due(1.0 + spec.realism.delay_s);
        let r = &frames[0].robots_blue[0];
        assert!(r.x != -2000.0 && (r.x + 2000.0).abs() < 10.0, "{}", r.x);
        assert!((frames[0].t_sent - frames[0].t_capture - 0.035).abs() < 1e-9);
        // A robot right beside the ball, on the side away from camera 1 (at +x, -y): the
        // camera over the field's other half sees the ball past it or not by the geometry.
        let cam = v.cameras[1];
        let b = Point3::new(500.0, -400.0, 21.5);
        let away = (b.xy() - cam.at_mm.xy()).normalize();
        let blocker = b.xy() + away * 60.0;
        c.robots = vec![robot(TeamColor::Yellow, 0, blocker.x, blocker.y)];
        assert!(cam.hidden(b, &c.robots));
        let aside = b.xy() - away * 200.0;
        c.robots = vec![robot(TeamColor::Yellow, 0, aside.x, aside.y)];
        assert!(!cam.hidden(b, &c.robots));
    }

    #[test]
    fn the_geometry_has_the_fields_size_and_a_camera_each() {
        let f = FieldPreset::DivisionB.spec();
        let v = OverheadVision::new(&SslVision::default(), &f, 21.5, 1);
        let g = v.geometry();
        assert_eq!(
            g.field.field_length,
            (2.0 * f.half_length_mm).round() as i32
        );
        assert_eq!(g.calib.len(), 4);
        assert!(g.field.field_lines.iter().any(|l| l.name == "HalfwayLine"));
    }
}
