//! The world and the robot as Foxglove's well-known messages: the static solids as a scene
//! (`foxglove.SceneUpdate`), poses and transforms, the free space the robot saw as a line.

use foxglove::messages::{
    Color, CubePrimitive, CylinderPrimitive, FrameTransform, LinePrimitive, Point3, Pose,
    PoseInFrame, Quaternion, SceneEntity, SceneUpdate, SpherePrimitive, Timestamp,
    TriangleListPrimitive, Vector3,
};
use nalgebra::Isometry2;
use omniloop_sim::shapes::{Solid, SolidShape};
use omniloop_vision::FreeSpace;

/// Millimetres to the metres Foxglove draws in.
const M: f64 = 1e-3;

/// The time `t_s` of the simulation as a message timestamp (the epoch is the run's start).
pub fn stamp(t_s: f64) -> Timestamp {
    Timestamp::saturating_from_epoch_secs_f64(t_s)
}

/// A planar pose (mm, rad) in metres, turned about z.
pub fn pose(p: &Isometry2<f64>, z_mm: f64) -> Pose {
    let half = 0.5 * p.rotation.angle();
    Pose {
        position: Some(Vector3 {
            x: p.translation.x * M,
            y: p.translation.y * M,
            z: z_mm * M,
        }),
        orientation: Some(Quaternion {
            x: 0.0,
            y: 0.0,
            z: half.sin(),
            w: half.cos(),
        }),
    }
}

/// `parent -> child` at pose `p`.
pub fn transform(t_s: f64, parent: &str, child: &str, p: &Isometry2<f64>) -> FrameTransform {
    let q = pose(p, 0.0);
    FrameTransform {
        timestamp: Some(stamp(t_s)),
        parent_frame_id: parent.into(),
        child_frame_id: child.into(),
        translation: q.position,
        rotation: q.orientation,
    }
}

/// Pose `p` in `frame`.
pub fn pose_in(t_s: f64, frame: &str, p: &Isometry2<f64>) -> PoseInFrame {
    PoseInFrame {
        timestamp: Some(stamp(t_s)),
        frame_id: frame.into(),
        pose: Some(pose(p, 0.0)),
    }
}

fn color(rgb: [u8; 3]) -> Color {
    Color {
        r: f64::from(rgb[0]) / 255.0,
        g: f64::from(rgb[1]) / 255.0,
        b: f64::from(rgb[2]) / 255.0,
        a: 1.0,
    }
}

fn point(x_mm: f64, y_mm: f64, z_mm: f64) -> Point3 {
    Point3 {
        x: x_mm * M,
        y: y_mm * M,
        z: z_mm * M,
    }
}

/// The world's solids (walls, cubes, pillars, boards) as one scene entity `world` in frame
/// `world`, each in its colour, and the floor (`floor`: the bounding box of `floor_mm`, if any).
pub fn world_scene(solids: &[Solid], floor: Option<([f64; 4], [u8; 3])>) -> SceneUpdate {
    let mut entity = SceneEntity {
        timestamp: Some(stamp(0.0)),
        frame_id: "world".into(),
        id: "world".into(),
        ..SceneEntity::default()
    };
    if let Some(([x0, y0, x1, y1], rgb)) = floor {
        entity.cubes.push(CubePrimitive {
            pose: Some(pose(
                &Isometry2::translation(0.5 * (x0 + x1), 0.5 * (y0 + y1)),
                -1.0,
            )),
            size: Some(Vector3 {
                x: (x1 - x0) * M,
                y: (y1 - y0) * M,
                z: 2.0 * M,
            }),
            color: Some(color(rgb)),
        });
    }
    for s in solids {
        let (h, z) = (s.height_mm - s.base_mm, 0.5 * (s.height_mm + s.base_mm));
        let c = Some(color(s.rgb.0));
        match &s.shape {
            SolidShape::Box {
                center_mm,
                half_extents_mm,
                angle_rad,
            } => entity.cubes.push(CubePrimitive {
                pose: Some(pose(&Isometry2::new(center_mm.coords, *angle_rad), z)),
                size: Some(Vector3 {
                    x: 2.0 * half_extents_mm.x * M,
                    y: 2.0 * half_extents_mm.y * M,
                    z: h * M,
                }),
                color: c,
            }),
            SolidShape::Cylinder {
                center_mm,
                radius_mm,
            } => entity.cylinders.push(CylinderPrimitive {
                pose: Some(pose(&Isometry2::translation(center_mm.x, center_mm.y), z)),
                size: Some(Vector3 {
                    x: 2.0 * radius_mm * M,
                    y: 2.0 * radius_mm * M,
                    z: h * M,
                }),
                bottom_scale: 1.0,
                top_scale: 1.0,
                color: c,
            }),
            SolidShape::Quad { corners_mm } => {
                entity
                    .triangles
                    .push(prism(corners_mm, s.base_mm, s.height_mm, c));
            }
        }
    }
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![entity],
    }
}

/// The things that move without software at `t_s`: the ball (a sphere) and the scripted
/// robots (cylinders), in the world frame.
pub fn moving(
    t_s: f64,
    ball: Option<(&crate::run::BallRow, &omniloop_sim::BallSpec)>,
    others: &[Solid],
) -> SceneUpdate {
    let mut scene = world_scene(others, None);
    for e in &mut scene.entities {
        e.timestamp = Some(stamp(t_s));
        e.id = "moving".into();
    }
    if let (Some((b, spec)), Some(e)) = (ball, scene.entities.first_mut()) {
        let d = 2.0 * spec.radius_mm * M;
        e.spheres.push(SpherePrimitive {
            pose: Some(pose(&Isometry2::translation(b.x_mm, b.y_mm), b.z_mm)),
            size: Some(Vector3 { x: d, y: d, z: d }),
            color: Some(color(spec.rgb.0)),
        });
    }
    scene
}

/// A prism over the quadrilateral `q` from `z0` to `z1` (mm) as triangles: its top and sides.
fn prism(
    q: &[nalgebra::Point2<f64>; 4],
    z0: f64,
    z1: f64,
    c: Option<Color>,
) -> TriangleListPrimitive {
    let mut points = Vec::new();
    let v = |p: &nalgebra::Point2<f64>, z: f64| point(p.x, p.y, z);
    for tri in [[0, 1, 2], [0, 2, 3]] {
        points.extend(tri.map(|k| v(&q[k], z1)));
    }
    for k in 0..4 {
        let (a, b) = (&q[k], &q[(k + 1) % 4]);
        points.extend([v(a, z0), v(b, z0), v(b, z1), v(a, z0), v(b, z1), v(a, z1)]);
    }
    TriangleListPrimitive {
        pose: Some(pose(&Isometry2::identity(), 0.0)),
        points,
        color: c,
        ..TriangleListPrimitive::default()
    }
}

/// The free distance of every direction as a closed line in `frame` (the robot's), 1 cm above
/// the floor: where the robot believed the floor ended.
pub fn free_space(t_s: f64, frame: &str, fs: &FreeSpace) -> SceneUpdate {
    let mut points: Vec<Point3> = fs
        .direction_rad
        .iter()
        .zip(&fs.free_mm)
        .map(|(a, d)| point(d * a.cos(), d * a.sin(), 10.0))
        .collect();
    if let Some(first) = points.first().cloned() {
        points.push(first);
    }
    polyline(t_s, frame, "free_space", points, [230, 120, 20])
}

/// The planned path (world mm) as a line in frame `world`.
pub fn path(t_s: f64, path_mm: &[nalgebra::Point2<f64>]) -> SceneUpdate {
    let points = path_mm.iter().map(|p| point(p.x, p.y, 12.0)).collect();
    polyline(t_s, "world", "path", points, [40, 90, 220])
}

/// One entity `id` in `frame`: a line through `points` (metres), 1 cm thick.
fn polyline(t_s: f64, frame: &str, id: &str, points: Vec<Point3>, rgb: [u8; 3]) -> SceneUpdate {
    let line = LinePrimitive {
        r#type: 0,
        pose: Some(pose(&Isometry2::identity(), 0.0)),
        thickness: 0.01,
        scale_invariant: false,
        points,
        color: Some(color(rgb)),
        ..LinePrimitive::default()
    };
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![SceneEntity {
            timestamp: Some(stamp(t_s)),
            frame_id: frame.into(),
            id: id.into(),
            lines: vec![line],
            ..SceneEntity::default()
        }],
    }
}
