//! The CPU reference renderer: packets of eight rays, on every core.
//!
//! The mirror half of each pixel's path does not depend on the robot's pose, so it is traced
//! once per sensor in `f64` and kept, sorted into packets of eight rays of neighbouring azimuth
//! and elevation; every frame then transforms a packet's rays to the world and traces the
//! scene in `f32` eight lanes at a time ([`packet`]), with the operations of [`super::trace`].
//! Primitives are binned per frame into azimuth sectors around the sensor's axis and sorted by
//! distance, so a ray that meets the floor near the robot tests only the few primitives nearer
//! than that. A box's or quad's distance is that of its part inside the sector's wedge (a long
//! wall is far in the sectors that look along it). The binning is conservative, and equal
//! distances go to the primitive first in the scene's order, so the image is the same as
//! tracing every primitive ([`render_reference`]).
//!
//! Further savings leave every value as it was: a primitive the rays pass over (above its top
//! until past its footprint) is not tested, and a ray leaving above everything without going
//! down is sky at once; the shaded colours of the floor's paints, the sky, a cylinder's top and
//! every face of a quad prism or plain box are computed once a frame; only the packets whose
//! rays may meet the robot's own body test it.

mod packet;

use super::scene::{BoxPrim, QuadPrim, RANKED, Scene, SceneList, rank_slot};
use super::trace::{self, BLACK, FloorPaint, Hit, V3};
use crate::sensor::Sensor;
use nalgebra::Isometry2;
use packet::{FrameRays, LANES, Outputs, Packet, Scatter};
use rayon::prelude::*;
use std::sync::OnceLock;

/// The cached mirror half of one pixel, in the robot frame.
#[derive(Debug, Clone, Copy)]
struct PixelRay {
    o: V3,
    d: V3,
    /// Azimuth of `d` in the robot frame, in turns as a 32-bit fraction (so that adding the
    /// robot's heading wraps by itself). Its lowest bit (2^-32 turn, far finer than the
    /// sectors' slack) says whether the ray may meet the robot's body
    /// ([`SensorRays::prepare_body`]).
    azimuth: u32,
    /// Horizontal length of `d`; negative for a pixel that sees no mirror (so that a ray is
    /// 32 bytes, two to a cache line).
    d_xy: f32,
}

impl PixelRay {
    /// Whether the pixel sees the mirror.
    fn valid(&self) -> bool {
        self.d_xy >= 0.0
    }

    /// Whether the ray may meet the robot's body.
    fn may_meet_body(&self) -> bool {
        self.azimuth & 1 == 1
    }
}

/// Per-sensor cache of pixel rays.
#[derive(Debug, Clone)]
pub struct SensorRays {
    rays: Vec<PixelRay>,
    axis: [f32; 2],
    max_offset_mm: f32,
    /// The robot body's radius and height (bits) for which each ray's body flag is set: the
    /// body is fixed to the sensor, so the flags hold for every pose.
    body: Option<[u32; 2]>,
    /// The rays that see the mirror, in packets of neighbouring azimuth (and elevation), made
    /// at the first frame that needs them.
    packets: Vec<Packet>,
    /// Whether the packets are ordered by elevation within their azimuth bucket too.
    by_elevation: bool,
    /// The pixels that see no mirror.
    blind: Vec<u32>,
}

/// Whether the ray `o + t d` (`t > 0`) comes within `r` of the vertical axis through the
/// origin somewhere at a height between 0 and `top` (in `f64`: a conservative test).
fn may_meet_cylinder(o: V3, d: V3, r: f32, top: f32) -> bool {
    let (ox, oy, oz) = (o[0] as f64, o[1] as f64, o[2] as f64);
    let (dx, dy, dz) = (d[0] as f64, d[1] as f64, d[2] as f64);
    // The part of the ray between the heights 0 and top.
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    if dz.abs() < 1e-12 {
        if oz < 0.0 || oz > top as f64 {
            return false;
        }
    } else {
        let (a, b) = ((0.0 - oz) / dz, (top as f64 - oz) / dz);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    if t0 > t1 {
        return false;
    }
    // Closest horizontal approach to the axis on [t0, t1].
    let a = dx * dx + dy * dy;
    let t = if a < 1e-24 {
        t0
    } else {
        (-(ox * dx + oy * dy) / a).clamp(t0, t1.min(1e12))
    };
    let (x, y) = (ox + t * dx, oy + t * dy);
    x * x + y * y <= (r as f64) * (r as f64)
}

impl SensorRays {
    /// Traces the mirror half of every pixel of `sensor`.
    pub fn new(sensor: &Sensor) -> Self {
        Self::traced(sensor, true)
    }

    /// [`SensorRays::new`] for a sensor traced again at every frame (a camera on a pan unit):
    /// its packets are ordered by azimuth alone, in one pass over the rays, not sorted by
    /// elevation too (a little slower to trace, much quicker to make).
    pub fn retraced(sensor: &Sensor) -> Self {
        Self::traced(sensor, false)
    }

    fn traced(sensor: &Sensor, by_elevation: bool) -> Self {
        let mut rays = Vec::with_capacity((sensor.width_px * sensor.height_px) as usize);
        // The farthest a ray starts from the axis: the optics' bound, or beyond it where a
        // mirror is mounted off its place.
        let mut max_offset = sensor.optics.max_origin_offset_mm();
        sensor.for_each_pixel_ray(|ray| {
            rays.push(match ray {
                Some(r) => {
                    let axis_offset =
                        (r.origin.x - sensor.mount_mm[0]).hypot(r.origin.y - sensor.mount_mm[1]);
                    max_offset = max_offset.max(axis_offset);
                    let d = [r.dir.x as f32, r.dir.y as f32, r.dir.z as f32];
                    PixelRay {
                        o: [r.origin.x as f32, r.origin.y as f32, r.origin.z as f32],
                        d,
                        // The body flag's bit clear until the body is known.
                        azimuth: turns(d[1].atan2(d[0]) as f64) & !1,
                        d_xy: (d[0] * d[0] + d[1] * d[1]).sqrt(),
                    }
                }
                None => PixelRay {
                    o: [0.0; 3],
                    d: [0.0; 3],
                    azimuth: 0,
                    d_xy: -1.0,
                },
            });
        });
        Self {
            rays,
            axis: [sensor.mount_mm[0] as f32, sensor.mount_mm[1] as f32],
            max_offset_mm: max_offset as f32,
            body: None,
            packets: Vec::new(),
            by_elevation,
            blind: Vec::new(),
        }
    }

    /// Makes the packets if they are not made (at the first frame, or after the body's flags
    /// changed).
    fn prepare_packets(&mut self) {
        if self.packets.is_empty() {
            (self.packets, self.blind) = packets(&self.rays, self.by_elevation);
        }
    }

    /// Whether each pixel's ray may meet an upright cylinder of `radius` and height `top` at
    /// the robot's centre, with [`BODY_MARGIN_MM`] to spare (exact arithmetic on the cached
    /// robot-frame rays; the margin covers the rounding of the world-frame test it spares).
    fn prepare_body(&mut self, radius: f32, top: f32) {
        let key = [radius.to_bits(), top.to_bits()];
        if self.body != Some(key) {
            let r = radius + BODY_MARGIN_MM;
            let z_top = top + BODY_MARGIN_MM;
            for ray in &mut self.rays {
                let meets = ray.valid() && may_meet_cylinder(ray.o, ray.d, r, z_top);
                ray.azimuth = (ray.azimuth & !1) | meets as u32;
            }
            self.packets.clear();
            self.body = Some(key);
        }
    }
}

/// Azimuth buckets (a power of two) of the packets' order: eight to a sector, so that a
/// bucket's rays fall in at most two sectors whatever the heading.
const BUCKETS: u32 = 256;

/// The rays that see the mirror in packets, and the pixels that see no mirror. The rays that
/// may meet the robot's body come first; each part is ordered by azimuth bucket, then
/// elevation, so that a packet's rays meet the same primitives.
fn packets(rays: &[PixelRay], by_elevation: bool) -> (Vec<Packet>, Vec<u32>) {
    let blind: Vec<u32> = (0..rays.len() as u32)
        .filter(|&k| !rays[k as usize].valid())
        .collect();
    let seen = if by_elevation {
        let mut keys: Vec<u128> = (0..rays.len() as u32)
            .filter(|&k| rays[k as usize].valid())
            .map(|k| packet_order(&rays[k as usize], k))
            .collect();
        // The keys are distinct (each holds its pixel), so an unstable sort gives one order.
        keys.sort_unstable();
        keys.iter().map(|&key| key as u32).collect()
    } else {
        by_bucket(rays)
    };
    let packets = seen
        .chunks(LANES)
        .map(|chunk| {
            let mut p = Packet::default();
            for lane in 0..LANES {
                // A short last packet repeats its last ray (the same pixel, the same colour).
                let k = chunk[lane.min(chunk.len() - 1)];
                let r = &rays[k as usize];
                for axis in 0..3 {
                    p.o[axis][lane] = r.o[axis];
                    p.d[axis][lane] = r.d[axis];
                }
                p.d_xy[lane] = r.d_xy;
                p.floor_t[lane] = trace::floor_t(r.o, r.d).unwrap_or(-1.0);
                p.inv_dz[lane] = 1.0 / r.d[2];
                p.azimuth[lane] = r.azimuth;
                p.pixel[lane] = k;
                p.may_meet_body |= r.may_meet_body();
            }
            p
        })
        .collect();
    (packets, blind)
}

/// The rays that see the mirror, those that may meet the body first, then by azimuth bucket,
/// each class in pixel order (a counting sort).
fn by_bucket(rays: &[PixelRay]) -> Vec<u32> {
    let class = |r: &PixelRay| {
        let bucket = (r.azimuth / (u32::MAX / BUCKETS + 1)) as usize;
        usize::from(!r.may_meet_body()) * BUCKETS as usize + bucket
    };
    let mut start = vec![0usize; 2 * BUCKETS as usize + 1];
    for r in rays.iter().filter(|r| r.valid()) {
        start[class(r) + 1] += 1;
    }
    for k in 1..start.len() {
        start[k] += start[k - 1];
    }
    let mut seen = vec![0; start[start.len() - 1]];
    for (k, r) in rays.iter().enumerate().filter(|(_, r)| r.valid()) {
        let c = class(r);
        seen[start[c]] = k as u32;
        start[c] += 1;
    }
    seen
}

/// A ray's place in the packets' order, as one number: first the rays that may meet the body,
/// then by azimuth bucket, then by elevation (`d_z`), up in even buckets and down in odd ones
/// (so that a packet across two buckets joins their ends of the same elevation), then by pixel.
fn packet_order(r: &PixelRay, pixel: u32) -> u128 {
    let bucket = r.azimuth / (u32::MAX / BUCKETS + 1);
    // `f32::total_cmp`'s order as an unsigned number.
    let z = r.d[2].to_bits();
    let up = if z >> 31 == 1 { !z } else { z | 1 << 31 };
    let elevation = if bucket.is_multiple_of(2) { up } else { !up };
    let body = u128::from(!r.may_meet_body());
    body << 72 | u128::from(bucket) << 64 | u128::from(elevation) << 32 | u128::from(pixel)
}

/// Margin (mm) by which a ray must miss the body, in the robot frame, to be left untested.
const BODY_MARGIN_MM: f32 = 1.0;

const SECTORS: usize = 256;

#[derive(Debug, Clone, Copy)]
enum Prim {
    Box(u32),
    Quad(u32),
    Cylinder(u32),
    Sphere(u32),
}

#[derive(Debug, Clone, Copy)]
struct Item {
    /// Horizontal distance (mm) from the sensor axis to the nearest point of the footprint.
    d_min: f32,
    /// Horizontal distance (mm) from the sensor axis to the farthest point of the footprint,
    /// plus the rays' largest offset from the axis and [`CULL_MARGIN_MM`].
    reach: f32,
    /// Height (mm) of the primitive's top, plus [`CULL_MARGIN_MM`].
    top: f32,
    prim: Prim,
}

/// Margin (mm) by which a ray must pass over a primitive to leave it untested: far more than
/// the rounding of the `f32` hit tests it spares.
const CULL_MARGIN_MM: f32 = 1.0;

impl Item {
    /// Whether a ray from height `oz` (mm) with direction `d` (horizontal length `d_xy`) stays
    /// above the primitive's top until it is farther from the axis than the whole footprint:
    /// above the top while `t < (oz - top) / -d_z`, beyond the footprint once
    /// `t d_xy - rho > d_max`, that is `t > reach / d_xy`.
    fn passes_over(&self, oz: f32, dz: f32, d_xy: f32) -> bool {
        let above = oz - self.top;
        above > 0.0 && (dz >= 0.0 || above * d_xy > self.reach * -dz)
    }
}

/// Primitives binned by azimuth around the sensor axis, each bin sorted by distance. The
/// buffers are kept between frames.
#[derive(Debug, Default)]
struct Sectors {
    offsets: Vec<u32>,
    items: Vec<Item>,
    /// (sector, item) pairs before sorting.
    pairs: Vec<(u16, Item)>,
    /// Each quad prism's sides, prepared once a frame.
    quad_sides: Vec<trace::QuadSides>,
    /// Each quad prism's shaded, packed colour on each face ([`trace::QuadFace::index`]).
    quad_faces: Vec<FaceColours>,
    /// Each box's shaded, packed colour on each face ([`trace::BoxFace::index`]); a striped
    /// board's are shaded as it is hit.
    box_faces: Vec<FaceColours>,
    /// The shaded, packed colour of each floor paint: one per floor rectangle, then outside,
    /// line and bare floor.
    palette: Vec<u32>,
    /// The palette in one register's lanes, where it fits (up to five floor rectangles).
    palette_lanes: Option<[u32; LANES]>,
    /// The packed colour of the sky.
    sky: u32,
    /// Each cylinder's shaded, packed colour on its top.
    cylinder_tops: Vec<u32>,
    /// The highest top of any primitive plus [`CULL_MARGIN_MM`]: a ray from above it that does
    /// not go down meets nothing.
    top_mm: f32,
    /// The rank of each ranked list's first primitive ([`Scene::first_ranks`]), for
    /// [`Sectors::rank`].
    first_ranks: [u32; RANKED.len()],
}

/// The shaded, packed colours of a primitive's six faces in the order of their `index`, and two
/// unused lanes (so that a packet reads them as one register).
type FaceColours = [u32; LANES];

fn face_colours(faces: [u32; 6]) -> FaceColours {
    let mut lanes = [0; LANES];
    lanes[..6].copy_from_slice(&faces);
    lanes
}

/// An angle (rad) as a fraction of a turn in 32 bits (wrapping).
fn turns(a: f64) -> u32 {
    (a / std::f64::consts::TAU * 4_294_967_296.0).rem_euclid(4_294_967_296.0) as u64 as u32
}

/// The bits of a turn below a sector's index.
const SECTOR_SHIFT: u32 = 32 - SECTORS.trailing_zeros();

fn wrap(a: f32) -> f32 {
    let t = std::f32::consts::TAU;
    a - (a / t).floor() * t
}

/// The sector span of a primitive that surrounds the axis: every azimuth.
const AROUND: (f32, f32) = (0.0, std::f32::consts::PI);

/// The largest angle (rad) between `centre` and the azimuth of one of `corners`.
fn half_angle(corners: &[[f32; 2]], centre: f32) -> f32 {
    corners.iter().fold(0.0, |half: f32, c| {
        let mut da = c[1].atan2(c[0]) - centre;
        da -= (da / std::f32::consts::TAU).round() * std::f32::consts::TAU;
        half.max(da.abs())
    })
}

/// Distance from the origin to the farthest of `corners`.
fn farthest(corners: &[[f32; 2]]) -> f32 {
    corners
        .iter()
        .map(|c| (c[0] * c[0] + c[1] * c[1]).sqrt())
        .fold(0.0, f32::max)
}

/// Distance from the origin to a convex polygon given relative to it (counter-clockwise), and
/// whether the origin lies inside.
fn polygon_distance(corners: &[[f32; 2]]) -> (f32, bool) {
    let n = corners.len();
    let mut inside = true;
    let mut best = f32::INFINITY;
    for i in 0..n {
        let a = corners[i];
        let b = corners[(i + 1) % n];
        let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
        let len2 = ex * ex + ey * ey;
        if len2 < 1e-12 {
            continue;
        }
        // The origin is outside when it lies right of a side: cross(e, -a) < 0.
        if ex * -a[1] - ey * -a[0] < 0.0 {
            inside = false;
        }
        let u = ((-a[0] * ex - a[1] * ey) / len2).clamp(0.0, 1.0);
        let (px, py) = (a[0] + u * ex, a[1] + u * ey);
        best = best.min((px * px + py * py).sqrt());
    }
    (best, inside)
}

/// The nearest and farthest distance (mm) from the axis of the part of a convex polygon
/// (`corners` relative to the axis) inside the wedge of `sector` widened by half a sector and
/// by `spread` (rad) on either side, or `None` where the wedge misses it. The wedge holds every
/// point that a ray of the sector, starting within the rays' offset of the axis, can reach on
/// the polygon (`spread` = asin(offset / distance of the polygon)); the half sector covers the
/// rounding of the rays' sectors. `spread` is given by its cosine and sine. In `f64`, whose
/// rounding the culling margins cover.
fn wedge_extent(corners: &[[f32; 2]; 4], sector: u16, spread: (f64, f64)) -> Option<(f32, f32)> {
    let [c0, s0, c1, s1] = sector_edges()[sector as usize];
    let (cs, ss) = spread;
    // The wedge's edges, turned outwards by the spread.
    let (c0, s0) = (c0 * cs + s0 * ss, s0 * cs - c0 * ss);
    let (c1, s1) = (c1 * cs - s1 * ss, s1 * cs + c1 * ss);
    // Left of the first edge and right of the second (the wedge is narrower than a half turn).
    let mut poly = Polygon::default();
    for c in corners {
        poly.push([c[0] as f64, c[1] as f64]);
    }
    let poly = poly.clip([-s0, c0]).clip([s1, -c1]);
    if poly.n == 0 {
        return None;
    }
    let pts = &poly.pts[..poly.n];
    let far = pts
        .iter()
        .map(|p| p[0] * p[0] + p[1] * p[1])
        .fold(0.0, f64::max)
        .sqrt();
    let near = (0..pts.len())
        .map(|i| segment_distance(pts[i], pts[(i + 1) % pts.len()]))
        .fold(f64::INFINITY, f64::min);
    Some((near as f32, far as f32))
}

/// The cosine and sine of each sector's wedge edges, widened by half a sector on either side:
/// `[cos a0, sin a0, cos a1, sin a1]`.
fn sector_edges() -> &'static [[f64; 4]; SECTORS] {
    static EDGES: OnceLock<[[f64; 4]; SECTORS]> = OnceLock::new();
    EDGES.get_or_init(|| {
        let width = std::f64::consts::TAU / SECTORS as f64;
        std::array::from_fn(|k| {
            let (a0, a1) = ((k as f64 - 0.5) * width, (k as f64 + 1.5) * width);
            [a0.cos(), a0.sin(), a1.cos(), a1.sin()]
        })
    })
}

/// Distance from the origin to the segment `a b`.
fn segment_distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
    let len2 = ex * ex + ey * ey;
    let u = if len2 > 0.0 {
        ((-a[0] * ex - a[1] * ey) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (x, y) = (a[0] + u * ex, a[1] + u * ey);
    (x * x + y * y).sqrt()
}

/// A small convex polygon (a quadrilateral clipped by up to two half-planes).
#[derive(Debug, Default, Clone, Copy)]
struct Polygon {
    pts: [[f64; 2]; 6],
    n: usize,
}

impl Polygon {
    fn push(&mut self, p: [f64; 2]) {
        if self.n < self.pts.len() {
            self.pts[self.n] = p;
            self.n += 1;
        }
    }

    /// The part where `normal . p >= 0` (Sutherland and Hodgman's step, for a half-plane
    /// through the origin).
    fn clip(&self, normal: [f64; 2]) -> Polygon {
        let mut out = Polygon::default();
        let side = |p: [f64; 2]| normal[0] * p[0] + normal[1] * p[1];
        for i in 0..self.n {
            let (p, q) = (self.pts[i], self.pts[(i + 1) % self.n]);
            let (fp, fq) = (side(p), side(q));
            if fp >= 0.0 {
                out.push(p);
            }
            if (fp >= 0.0) != (fq >= 0.0) {
                let u = fp / (fp - fq);
                out.push([p[0] + u * (q[0] - p[0]), p[1] + u * (q[1] - p[1])]);
            }
        }
        out
    }
}

impl Sectors {
    /// Prepares, for this frame's scene, each quad prism's sides and the shaded colours that do
    /// not depend on the ray: every face of the quads and boxes, the floor's paints, the sky;
    /// and the highest top.
    fn prepare_faces(&mut self, scene: &Scene) {
        let shaded = |n: V3, rgb: V3| trace::pack(trace::shade(scene, &Hit { t: 0.0, n, rgb }));
        self.quad_sides.clear();
        self.quad_sides
            .extend(scene.quads.iter().map(trace::quad_sides));
        self.box_faces.clear();
        self.box_faces.extend(scene.boxes.iter().map(|b| {
            let rgb = [b.color[0], b.color[1], b.color[2]];
            face_colours(trace::BoxFace::ALL.map(|f| shaded(f.normal(b), rgb)))
        }));
        self.quad_faces.clear();
        self.quad_faces
            .extend(scene.quads.iter().zip(&self.quad_sides).map(|(q, sides)| {
                let rgb = [q.color[0], q.color[1], q.color[2]];
                face_colours(trace::QuadFace::ALL.map(|f| shaded(f.normal(sides), rgb)))
            }));
        let paints = (0..scene.floor_rects.len()).map(FloorPaint::Mark).chain([
            FloorPaint::Outside,
            FloorPaint::Line,
            FloorPaint::Floor,
        ]);
        self.cylinder_tops.clear();
        self.cylinder_tops.extend(
            (scene.cylinders.iter())
                .map(|c| shaded([0.0, 0.0, 1.0], [c.top[0], c.top[1], c.top[2]])),
        );
        self.palette.clear();
        self.palette.extend(
            paints.map(|paint| shaded(trace::FLOOR_NORMAL, trace::paint_color(scene, paint))),
        );
        self.palette_lanes = (self.palette.len() <= LANES).then(|| {
            let mut lanes = [0; LANES];
            lanes[..self.palette.len()].copy_from_slice(&self.palette);
            lanes
        });
        let g = &scene.globals;
        self.sky = trace::pack([g.sky_rgb[0], g.sky_rgb[1], g.sky_rgb[2]]);
        let tops = (scene.boxes.iter().map(|b| b.frame[3]))
            .chain(scene.quads.iter().map(|q| q.z[0]))
            .chain(scene.cylinders.iter().map(|c| c.geom[3]))
            .chain(scene.spheres.iter().map(|s| s.geom[2] + s.geom[3]));
        self.top_mm = tops.fold(f32::NEG_INFINITY, f32::max) + CULL_MARGIN_MM;
        self.first_ranks = scene.first_ranks();
    }

    /// A primitive's place in the scene's order, from 1 (0 is the floor's).
    fn rank(&self, prim: Prim) -> u32 {
        let first = &self.first_ranks;
        match prim {
            Prim::Box(i) => first[const { rank_slot(SceneList::Boxes) }] + i,
            Prim::Quad(i) => first[const { rank_slot(SceneList::Quads) }] + i,
            Prim::Cylinder(i) => first[const { rank_slot(SceneList::Cylinders) }] + i,
            Prim::Sphere(i) => first[const { rank_slot(SceneList::Spheres) }] + i,
        }
    }

    /// Bins the scene's primitives for a sensor axis at `axis` whose rays start up to `rho` mm
    /// from it, leaving out cylinder `body` (the robot's own, which the rays that may meet it
    /// test first).
    fn rebuild(&mut self, scene: &Scene, axis: [f32; 2], rho: f32, body: Option<usize>) {
        self.prepare_faces(scene);
        self.pairs.clear();
        let mut bins = Binning {
            pairs: &mut self.pairs,
            axis,
            rho,
        };
        for (i, b) in scene.boxes.iter().enumerate() {
            bins.add_box(i as u32, b);
        }
        for (i, q) in scene.quads.iter().enumerate() {
            bins.add_quad(i as u32, q);
        }
        for (i, cyl) in scene.cylinders.iter().enumerate() {
            if Some(i) == body {
                continue;
            }
            let [cx, cy, r, top] = cyl.geom;
            bins.add_disc(Prim::Cylinder(i as u32), [cx, cy, r], top);
        }
        for (i, sp) in scene.spheres.iter().enumerate() {
            let [cx, cy, cz, r] = sp.geom;
            bins.add_disc(Prim::Sphere(i as u32), [cx, cy, r], cz + r);
        }
        // A stable sort keeps the scene's order among equal distances, so that exact ties
        // (coplanar faces) resolve as when every primitive is traced.
        self.pairs
            .sort_by(|a, b| a.0.cmp(&b.0).then(a.1.d_min.total_cmp(&b.1.d_min)));
        self.items.clear();
        self.offsets.clear();
        self.offsets.push(0);
        let mut next = 0;
        for k in 0..SECTORS as u16 {
            while next < self.pairs.len() && self.pairs[next].0 == k {
                self.items.push(self.pairs[next].1);
                next += 1;
            }
            self.offsets.push(self.items.len() as u32);
        }
    }
}

/// The (sector, item) pairs of a frame's primitives, as they are binned around the sensor axis
/// at `axis` (world frame), whose rays start up to `rho` mm from it.
struct Binning<'a> {
    pairs: &'a mut Vec<(u16, Item)>,
    axis: [f32; 2],
    rho: f32,
}

impl Binning<'_> {
    /// Puts `prim` in every sector whose rays may meet it: its footprint lies from `d_min` to
    /// `d_max` from the axis, below `top`, within `half` (rad) of the azimuth `centre`; a
    /// polygon's `corners` (relative to the axis) narrow its distances sector by sector.
    fn add(
        &mut self,
        prim: Prim,
        (d_min, d_max, top): (f32, f32, f32),
        (centre, half): (f32, f32),
        corners: Option<&[[f32; 2]; 4]>,
    ) {
        let rho = self.rho;
        let item = Item {
            d_min,
            reach: d_max + rho + CULL_MARGIN_MM,
            top: top + CULL_MARGIN_MM,
            prim,
        };
        if d_min <= 2.0 * rho + 1.0 || half >= std::f32::consts::PI {
            self.pairs.extend((0..SECTORS).map(|k| (k as u16, item)));
            return;
        }
        let spread = (rho / d_min).min(1.0).asin();
        let spread_cs = ((spread as f64).cos(), (spread as f64).sin());
        let half = half + spread;
        let width = std::f32::consts::TAU / SECTORS as f32;
        // One sector to spare on either side: rays find their sector from 32-bit turns.
        let start = ((wrap(centre - half)) / width).floor() as i64 - 1;
        let n = ((2.0 * half) / width).ceil() as i64 + 1;
        for k in start..=start + n + 1 {
            let sector = k.rem_euclid(SECTORS as i64) as u16;
            let Some(corners) = corners else {
                self.pairs.push((sector, item));
                continue;
            };
            // A polygon's part that the sector's rays can reach: nearer and farther than the
            // whole footprint, or none at all.
            if let Some((near, far)) = wedge_extent(corners, sector, spread_cs) {
                let item = Item {
                    d_min: near.max(d_min),
                    reach: far.min(d_max) + rho + CULL_MARGIN_MM,
                    ..item
                };
                self.pairs.push((sector, item));
            }
        }
    }

    /// Box `i`.
    fn add_box(&mut self, i: u32, b: &BoxPrim) {
        let axis = self.axis;
        let [cx, cy, hx, hy] = b.geom;
        let [c, s, _, top] = b.frame;
        let rx = axis[0] - cx;
        let ry = axis[1] - cy;
        let lx = (c * rx + s * ry).abs() - hx;
        let ly = (-s * rx + c * ry).abs() - hy;
        let d_min = (lx.max(0.0).powi(2) + ly.max(0.0).powi(2)).sqrt();
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(sx, sy)| {
            [
                cx + c * sx * hx - s * sy * hy - axis[0],
                cy + s * sx * hx + c * sy * hy - axis[1],
            ]
        });
        let d_max = farthest(&corners);
        if lx <= 0.0 && ly <= 0.0 {
            self.add(Prim::Box(i), (0.0, d_max, top), AROUND, None);
            return;
        }
        let centre = (cy - axis[1]).atan2(cx - axis[0]);
        let half = half_angle(&corners, centre);
        let extent = (d_min, d_max, top);
        self.add(Prim::Box(i), extent, (centre, half), Some(&corners));
    }

    /// Quad prism `i`.
    fn add_quad(&mut self, i: u32, q: &QuadPrim) {
        let axis = self.axis;
        let corners = [0, 1, 2, 3].map(|k| {
            let c = q.corner(k);
            [c[0] - axis[0], c[1] - axis[1]]
        });
        let (d_min, inside) = polygon_distance(&corners);
        let (d_max, top) = (farthest(&corners), q.z[0]);
        if inside {
            self.add(Prim::Quad(i), (0.0, d_max, top), AROUND, None);
            return;
        }
        let (sx, sy) = corners
            .iter()
            .fold((0.0, 0.0), |(x, y), c| (x + c[0], y + c[1]));
        let centre = sy.atan2(sx);
        let half = half_angle(&corners, centre);
        let extent = (d_min, d_max, top);
        self.add(Prim::Quad(i), extent, (centre, half), Some(&corners));
    }

    /// A primitive standing over the disc of centre `(cx, cy)` and radius `r` of the floor, its
    /// top at `top` (a cylinder; a sphere, wherever its centre is above the floor).
    fn add_disc(&mut self, prim: Prim, [cx, cy, r]: [f32; 3], top: f32) {
        let dx = cx - self.axis[0];
        let dy = cy - self.axis[1];
        let dc = (dx * dx + dy * dy).sqrt();
        if dc <= r {
            self.add(prim, (0.0, dc + r, top), AROUND, None);
            return;
        }
        let span = (dy.atan2(dx), (r / dc).asin());
        self.add(prim, (dc - r, dc + r, top), span, None);
    }
}

/// Renders RGBA8 frames on the CPU.
#[derive(Debug, Default)]
pub struct CpuRenderer {
    sectors: Sectors,
    /// Whether to trace without the processor's vector instructions.
    portable: bool,
}

impl CpuRenderer {
    /// A renderer, in the widest vector instructions the processor has.
    pub fn new() -> Self {
        Self::default()
    }

    /// A renderer that uses no vector instructions chosen at run time: the reference its
    /// vector kernel is checked against (the images are the same to the bit).
    pub fn portable() -> Self {
        Self {
            portable: true,
            ..Self::default()
        }
    }

    /// Renders one frame: `rays` of a sensor on a robot at `pose`, into packed RGBA8 pixels
    /// (`pixels.len() == width * height`).
    pub fn render(
        &mut self,
        scene: &Scene,
        rays: &mut SensorRays,
        pose: &Isometry2<f64>,
        pixels: &mut [u32],
    ) {
        self.trace(scene, rays, pose, pixels, None);
    }

    /// [`CpuRenderer::render`] with each pixel's truth: the distance along its scene ray to
    /// what it meets (mm; infinity for the sky, NaN where it sees no mirror) into `t`, and
    /// what that is ([`trace::Code`]) into `code`. The colours are those `render` gives.
    pub fn render_truth(
        &mut self,
        scene: &Scene,
        rays: &mut SensorRays,
        pose: &Isometry2<f64>,
        pixels: &mut [u32],
        (t, code): (&mut [f32], &mut [u32]),
    ) {
        assert!(t.len() == pixels.len() && code.len() == pixels.len());
        self.trace(scene, rays, pose, &mut *pixels, Some((&mut *t, &mut *code)));
        // After tracing: the rays' blind pixels are known once their packets are made.
        for &k in &rays.blind {
            (t[k as usize], code[k as usize]) = (f32::NAN, trace::CODE_NOTHING);
        }
    }

    fn trace(
        &mut self,
        scene: &Scene,
        rays: &mut SensorRays,
        pose: &Isometry2<f64>,
        pixels: &mut [u32],
        truth: Option<(&mut [f32], &mut [u32])>,
    ) {
        assert_eq!(pixels.len(), rays.rays.len());
        let px = pose.translation.x as f32;
        let py = pose.translation.y as f32;
        let theta = pose.rotation.angle();
        let c = theta.cos() as f32;
        let s = theta.sin() as f32;
        let axis = [
            px + c * rays.axis[0] - s * rays.axis[1],
            py + s * rays.axis[0] + c * rays.axis[1],
        ];
        let rho = rays.max_offset_mm;
        // The robot's own body: the cylinder standing at its centre. The pixels whose rays
        // may meet it (the same for every pose) test it; the others leave it out.
        let body = scene
            .cylinders
            .iter()
            .position(|cy| cy.geom[0] == px && cy.geom[1] == py);
        self.sectors.rebuild(scene, axis, rho, body);
        if let Some(i) = body {
            let [_, _, r, top] = scene.cylinders[i].geom;
            rays.prepare_body(r, top);
        }
        rays.prepare_packets();
        let frame = FrameRays {
            scene,
            sectors: &self.sectors,
            pose: [px, py, c, s],
            heading: turns(theta),
            rho,
            body,
        };
        for &k in &rays.blind {
            pixels[k as usize] = BLACK;
        }
        let trace_chunk = packet::trace_chunk_fn(self.portable);
        let out = Outputs {
            colour: Scatter::new(pixels),
            truth: truth.map(|(t, code)| (Scatter::new(t), Scatter::new(code))),
        };
        // Chunks of packets small enough to share out over the cores, large enough to cost
        // little to hand out.
        rays.packets
            .par_chunks(32)
            .for_each(|chunk| trace_chunk(&frame, chunk, &out));
    }
}

/// Renders every primitive for every pixel, without binning (the reference of the tests).
pub fn render_reference(scene: &Scene, rays: &SensorRays, pose: &Isometry2<f64>) -> Vec<u32> {
    trace_reference(scene, rays, pose)
        .iter()
        .map(|r| r.colour)
        .collect()
}

/// [`render_reference`] with each pixel's distance and what it meets, as
/// [`CpuRenderer::render_truth`] gives them.
pub fn trace_reference(
    scene: &Scene,
    rays: &SensorRays,
    pose: &Isometry2<f64>,
) -> Vec<trace::Traced> {
    let px = pose.translation.x as f32;
    let py = pose.translation.y as f32;
    let theta = pose.rotation.angle();
    let c = theta.cos() as f32;
    let s = theta.sin() as f32;
    rays.rays
        .iter()
        .map(|r| {
            if !r.valid() {
                return trace::Traced {
                    colour: BLACK,
                    t: f32::NAN,
                    code: trace::CODE_NOTHING,
                };
            }
            let o = [
                px + c * r.o[0] - s * r.o[1],
                py + s * r.o[0] + c * r.o[1],
                r.o[2],
            ];
            let d = [c * r.d[0] - s * r.d[1], s * r.d[0] + c * r.d[1], r.d[2]];
            trace::trace_ray(scene, o, d)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::scene::CylinderPrim;

    #[test]
    fn a_ray_that_meets_a_primitive_never_passes_over_it() {
        // A pillar 600 mm from the axis: rays from mirror heights in every direction.
        let pillar = CylinderPrim {
            geom: [600.0, 0.0, 60.0, 150.0],
            color: [0.5, 0.5, 0.5, 0.0],
            top: [0.5, 0.5, 0.5, 0.0],
        };
        let rho = 20.0;
        let item = Item {
            d_min: 540.0,
            reach: 660.0 + rho + CULL_MARGIN_MM,
            top: 150.0 + CULL_MARGIN_MM,
            prim: Prim::Cylinder(0),
        };
        let (mut hits, mut culled) = (0, 0);
        for k in 0..40_000u32 {
            let a = -0.2 + 0.4 * (k % 200) as f32 / 200.0;
            let e = -0.6 + 0.8 * (k / 200) as f32 / 200.0;
            let o = [
                rho * (k as f32).cos(),
                rho * (k as f32).sin(),
                151.0 + (k % 70) as f32,
            ];
            let d = [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()];
            let d_xy = (d[0] * d[0] + d[1] * d[1]).sqrt();
            let over = item.passes_over(o[2], d[2], d_xy);
            if trace::hit_cylinder(&pillar, o, d, f32::INFINITY).is_some() {
                hits += 1;
                assert!(!over, "ray {k} meets the pillar but passes over it");
            } else if over {
                culled += 1;
            }
        }
        assert!(
            hits > 1000 && culled > 10_000,
            "hits {hits}, culled {culled}"
        );
    }

    #[test]
    fn a_sectors_rays_meet_a_polygon_only_within_its_wedge_extent() {
        // A wall 600 mm from the axis, 2 m long, turned a little; rays start within rho.
        let rho = 20.0f64;
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(sx, sy)| {
            let (lx, ly) = (sx * 1000.0, sy * 25.0);
            [(c * lx - s * ly) as f32, (600.0 + s * lx + c * ly) as f32]
        });
        let d_min = 540.0f64;
        let spread = (rho / d_min).asin();
        let width = std::f64::consts::TAU / SECTORS as f64;
        let inside = |x: f64, y: f64| {
            let (dx, dy) = (x, y - 600.0);
            let (lx, ly) = (c * dx + s * dy, -s * dx + c * dy);
            lx.abs() <= 1000.0 && ly.abs() <= 25.0
        };
        let (mut met, mut narrowed) = (0, 0);
        for sector in 0..SECTORS as u16 {
            let extent = wedge_extent(&corners, sector, (spread.cos(), spread.sin()));
            if let Some((near, _)) = extent {
                narrowed += (near > 600.0) as u32;
            }
            for k in 0..200 {
                let a = (sector as f64 + k as f64 / 200.0) * width;
                let (oa, or) = (k as f64 * 2.4, rho * (k % 7) as f64 / 6.0);
                let (ox, oy) = (or * oa.cos(), or * oa.sin());
                for step in 0..400 {
                    let r = 500.0 + 5.0 * step as f64;
                    let (x, y) = (ox + r * a.cos(), oy + r * a.sin());
                    if !inside(x, y) {
                        continue;
                    }
                    met += 1;
                    let (near, far) = extent.expect("the sector's rays meet the wall");
                    let dist = x.hypot(y);
                    assert!(
                        dist >= near as f64 - 1e-3 && dist <= far as f64 + 1e-3,
                        "sector {sector}: {dist} outside {near}..{far}"
                    );
                }
            }
        }
        assert!(
            met > 10_000 && narrowed > 10,
            "met {met}, narrowed {narrowed}"
        );
    }

    #[test]
    fn a_ray_that_meets_the_body_is_never_left_untested() {
        let body = CylinderPrim {
            geom: [0.0, 0.0, 90.0, 110.0],
            color: [0.5, 0.5, 0.5, 0.0],
            top: [0.5, 0.5, 0.5, 0.0],
        };
        let (mut hits, mut spared) = (0, 0);
        for k in 0..20_000u32 {
            // Rays from above and beside the body in every direction (a fixed spiral).
            let a = k as f32 * 0.618_034 * std::f32::consts::TAU;
            let e = -1.4 + 2.6 * ((k * 7919) % 20_000) as f32 / 20_000.0;
            let o = [25.0 * a.cos(), 25.0 * a.sin(), 120.0 + (k % 90) as f32];
            let d = [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()];
            let flagged = may_meet_cylinder(o, d, 90.0 + BODY_MARGIN_MM, 110.0 + BODY_MARGIN_MM);
            if trace::hit_cylinder(&body, o, d, f32::INFINITY).is_some() {
                hits += 1;
                assert!(flagged, "ray {k} meets the body but was not flagged");
            } else if !flagged {
                spared += 1;
            }
        }
        assert!(hits > 1000 && spared > 5000, "hits {hits}, spared {spared}");
    }

    /// A field with a cube and a pillar around the corner paper's robot at the origin, and
    /// spheres: a ball on the floor, one 300 mm up, one half behind the pillar, one in the
    /// cube's face, a large one cut by the floor under the robot (around the axis: in every
    /// sector) and one just above the robot's body.
    fn sphere_scene() -> Scene {
        use crate::labels::{Class, ObjectId};
        use crate::sphere::Sphere;
        use crate::{Cube, FieldSpec, Layout, Pillar};
        let layout = Layout {
            field: Some(FieldSpec::default()),
            cubes: vec![Cube {
                center_mm: [-500.0, 250.0],
                size_mm: 130.0,
                angle_deg: 20.0,
                rgb: crate::Rgb([200, 40, 40]),
            }],
            pillars: vec![Pillar {
                center_mm: [0.0, -600.0],
                radius_mm: 60.0,
                height_mm: 250.0,
                rgb: crate::Rgb([90, 90, 200]),
            }],
            ..Layout::default()
        };
        let ball = |k: u32, [x, y, z]: [f64; 3], r: f64| Sphere {
            center_mm: [x, y, z],
            radius_mm: r,
            rgb: crate::Rgb([255, 120, 0]),
            object: ObjectId::new(Class::Ball, k),
        };
        Scene::new(&layout, &[]).with_spheres(&[
            ball(0, [400.0, 0.0, 21.5], 21.5),
            ball(1, [0.0, 700.0, 321.5], 21.5),
            ball(2, [75.0, -720.0, 21.5], 21.5),
            ball(3, [-440.0, 250.0, 60.0], 40.0),
            ball(4, [30.0, 10.0, -900.0], 950.0),
            ball(5, [60.0, 0.0, 140.0], 15.0),
        ])
    }

    #[test]
    fn spheres_give_every_kernel_the_pixels_of_tracing_every_primitive() {
        use crate::sensor::SensorSpec;
        let scene = sphere_scene();
        let first = scene.boxes.len() + scene.quads.len() + scene.cylinders.len();
        assert_eq!(scene.globals.counts[3], 6);
        assert_eq!(scene.objects.len(), first + 6);
        let sensor = SensorSpec::corner_paper("omni").build();
        let poses = [
            Isometry2::new(nalgebra::Vector2::zeros(), 0.0),
            Isometry2::new(nalgebra::Vector2::new(37.0, -21.0), 1.234_567),
            Isometry2::new(nalgebra::Vector2::new(-150.0, 90.0), -2.5),
        ];
        let mut rays = SensorRays::new(&sensor);
        let avx2 = cfg!(target_arch = "x86_64") && std::arch::is_x86_feature_detected!("avx2");
        eprintln!(
            "kernels: portable and {}",
            if avx2 { "AVX2" } else { "portable" }
        );
        let mut seen = [0usize; 6];
        for (k, pose) in poses.iter().enumerate() {
            let traced = trace_reference(&scene, &rays, pose);
            for (i, n) in seen.iter_mut().enumerate() {
                let rank = (first + 1 + i) as u32;
                *n += traced.iter().filter(|r| r.code == rank).count();
            }
            for (kind, mut r) in [
                ("vector", CpuRenderer::new()),
                ("portable", CpuRenderer::portable()),
            ] {
                let n = traced.len();
                let (mut pixels, mut t, mut codes) = (vec![0; n], vec![0.0; n], vec![0; n]);
                r.render_truth(&scene, &mut rays, pose, &mut pixels, (&mut t, &mut codes));
                let differ = (0..n)
                    .filter(|&i| {
                        let want = &traced[i];
                        (pixels[i], t[i].to_bits(), codes[i])
                            != (want.colour, want.t.to_bits(), want.code)
                    })
                    .count();
                assert_eq!(differ, 0, "pose {k}, {kind} kernel");
                let mut plain = vec![0; n];
                r.render(&scene, &mut rays, pose, &mut plain);
                assert_eq!(plain, pixels, "pose {k}, {kind} kernel without truth");
            }
        }
        eprintln!("sphere pixels over the poses: {seen:?}");
        assert!(seen.iter().all(|&n| n >= 10), "sphere pixels {seen:?}");
    }

    #[test]
    fn a_sphere_is_met_where_it_stands_and_shaded_by_its_normal() {
        let scene = Scene::new(&crate::layout::Layout::default(), &[]).with_spheres(&[
            crate::sphere::Sphere {
                center_mm: [500.0, 0.0, 300.0],
                radius_mm: 20.0,
                rgb: crate::Rgb([255, 255, 255]),
                object: crate::labels::ObjectId::of(crate::labels::Class::Ball),
            },
        ]);
        let sp = &scene.spheres[0];
        // Straight at it from 480 mm off, in its equator's plane: met 460 mm on, normal -x.
        let hit = trace::hit_sphere(sp, [20.0, 0.0, 300.0], [1.0, 0.0, 0.0], f32::INFINITY)
            .expect("a hit");
        assert_eq!((hit.t, hit.n), (460.0, [-1.0, 0.0, 0.0]));
        // Passing 1 mm over its top: a miss; from inside, its far side.
        assert!(trace::hit_sphere(sp, [0.0, 0.0, 321.0], [1.0, 0.0, 0.0], 1e9).is_none());
        let inside = trace::hit_sphere(sp, [500.0, 0.0, 300.0], [0.0, 0.0, 1.0], 1e9).unwrap();
        assert_eq!((inside.t, inside.n), (20.0, [0.0, 0.0, 1.0]));
        // Beyond the nearest hit so far: none.
        assert!(trace::hit_sphere(sp, [20.0, 0.0, 300.0], [1.0, 0.0, 0.0], 460.0).is_none());
        // Straight down on it: its top, rank 1, lit as the floor (normal +z).
        let traced = trace::trace_ray(&scene, [500.0, 0.0, 900.0], [0.0, 0.0, -1.0]);
        assert_eq!((traced.t, traced.code), (580.0, 1));
        let floor_lit = trace::shade(
            &scene,
            &Hit {
                t: 0.0,
                n: trace::FLOOR_NORMAL,
                rgb: [1.0; 3],
            },
        );
        assert_eq!(traced.colour, trace::pack(floor_lit));
    }
}
