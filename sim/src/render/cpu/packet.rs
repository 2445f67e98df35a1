//! The packet tracer: eight rays of one sensor at a time.
//!
//! Every function here is an operation of [`crate::render::trace`] written over eight lanes
//! (`[f32; 8]`), each branch a select: the same operations in the same order, so each lane's
//! colour is to the bit what tracing its ray alone gives (and what tracing every primitive
//! gives, [`super::render_reference`]). Where the processor has AVX2 (found at run time), the
//! same steps run in its 256-bit registers ([`avx2`]); this portable code is their reference.
//!
//! A packet's rays are neighbours in azimuth and elevation ([`super::SensorRays`] sorts them),
//! so its lanes almost always fall in one azimuth sector, hit the same primitives and stop at
//! the same place; lanes of another sector take a second pass over that sector's primitives. A
//! lane may test primitives its ray alone would have left untested (another lane's, or past its
//! own stopping point): the binning is conservative, so such a test never finds a hit nearer
//! than the lane's own, and equal distances go to the primitive first in the scene's order
//! whatever the order of the tests.

// Lanes are indexed alike across several arrays, so the loops over them say `i`.
#![allow(clippy::needless_range_loop)]

use super::{Item, Prim, SECTOR_SHIFT, Sectors};
use crate::render::scene::{
    BoxPrim, CylinderPrim, FLOOR_REGION, QuadPrim, SQUARE_MARK, Scene, SpherePrim,
};
use crate::render::trace::{self, BoxFace, T_EPS};

/// Rays in a packet.
pub(super) const LANES: usize = 8;

type F = [f32; LANES];
type U = [u32; LANES];
type M = [bool; LANES];

/// Eight rays of one sensor in the robot frame, as lanes.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Packet {
    /// Origins' x, y, z (mm).
    pub o: [F; 3],
    /// Unit directions' x, y, z.
    pub d: [F; 3],
    /// Horizontal lengths of the directions.
    pub d_xy: F,
    /// The distance along each ray to the floor, or -1 where it does not go down to it (the
    /// same in every pose: a pose turns and moves the rays but keeps their heights).
    pub floor_t: F,
    /// `1 / d_z` (the same in every pose).
    pub inv_dz: F,
    /// Azimuths in the robot frame, in turns as 32-bit fractions.
    pub azimuth: U,
    /// The pixel each lane colours (a short packet repeats its last ray).
    pub pixel: U,
    /// Whether any lane's ray may meet the robot's body.
    pub may_meet_body: bool,
}

/// What every packet of a frame shares: the scene, its binning and the robot's pose.
#[derive(Debug, Clone, Copy)]
pub(super) struct FrameRays<'a> {
    pub scene: &'a Scene,
    pub sectors: &'a Sectors,
    /// The robot's x, y (mm) and the cosine and sine of its heading.
    pub pose: [f32; 4],
    /// The robot's heading in turns as a 32-bit fraction.
    pub heading: u32,
    /// The rays' largest offset from the sensor axis (mm).
    pub rho: f32,
    /// The robot's own body among the scene's cylinders.
    pub body: Option<usize>,
}

/// A frame's pixels (colours, or one of the truth's values), written at the places of the
/// packets' lanes.
#[derive(Debug, Clone, Copy)]
pub(super) struct Scatter<T> {
    ptr: *mut T,
    len: usize,
}

// SAFETY: a `Scatter` is only written through `Scatter::write`, whose callers write each pixel
// from one packet only (the packets' pixels are a permutation of the frame's).
unsafe impl<T: Send> Send for Scatter<T> {}
// SAFETY: as for `Send`.
unsafe impl<T: Send> Sync for Scatter<T> {}

impl<T: Copy> Scatter<T> {
    pub(super) fn new(pixels: &mut [T]) -> Self {
        Self {
            ptr: pixels.as_mut_ptr(),
            len: pixels.len(),
        }
    }

    /// Writes `values` at the packet's pixels.
    ///
    /// # Safety
    /// No other thread reads or writes these pixels meanwhile, and the slice this was made
    /// from outlives the call.
    #[inline(always)]
    pub(super) unsafe fn write(&self, p: &Packet, values: &[T; LANES]) {
        for (&k, &c) in p.pixel.iter().zip(values) {
            let k = k as usize;
            assert!(k < self.len, "a packet's pixel lies outside the frame");
            // SAFETY: in bounds (just asserted); exclusive by the caller's contract.
            unsafe { self.ptr.add(k).write(c) };
        }
    }
}

/// Where a frame's packets write: the colours and, where the truth is asked for, each pixel's
/// distance along its scene ray and what it meets ([`trace::Code`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct Outputs {
    pub colour: Scatter<u32>,
    pub truth: Option<(Scatter<f32>, Scatter<u32>)>,
}

impl Outputs {
    /// Writes a packet's colours, and its truth where asked for.
    ///
    /// # Safety
    /// As [`Scatter::write`]: this packet alone writes its pixels.
    #[inline(always)]
    unsafe fn write(&self, p: &Packet, colours: &U, t: &F, code: &U) {
        // SAFETY: the caller's contract.
        unsafe {
            self.colour.write(p, colours);
            if let Some((ts, codes)) = &self.truth {
                ts.write(p, t);
                codes.write(p, code);
            }
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2;

/// Traces a chunk of a frame's packets, each pixel written once: `out` must be the frame the
/// packets were made for, and no other chunk may hold these packets.
pub(super) type TraceChunk = fn(&FrameRays, &[Packet], &Outputs);

/// The chunk tracer in the widest vector instructions this processor has (AVX2, chosen at run
/// time), or the portable one where `portable` asks for it.
pub(super) fn trace_chunk_fn(portable: bool) -> TraceChunk {
    #[cfg(target_arch = "x86_64")]
    if !portable && std::arch::is_x86_feature_detected!("avx2") {
        return |frame, packets, out| {
            // SAFETY: AVX2 was detected on this processor just above.
            unsafe { avx2::trace_chunk(frame, packets, out) }
        };
    }
    trace_chunk
}

/// The portable chunk tracer: eight lanes as arrays.
fn trace_chunk(frame: &FrameRays, packets: &[Packet], out: &Outputs) {
    for p in packets {
        let (colours, t, code) = trace_packet(frame, p);
        // SAFETY: the packets' pixels are a permutation of the frame's and each packet is in
        // one chunk only, so this chunk alone writes these pixels.
        unsafe { out.write(p, &colours, &t, &code) };
    }
}

/// The nearest hit of each lane so far: its distance (the floor's to begin with, else
/// infinity), its primitive's rank in the scene's order and its packed colour.
#[derive(Debug, Clone, Copy)]
struct Nearest {
    t_max: F,
    rank: U,
    colour: U,
    hit: M,
}

impl Nearest {
    /// The distance a hit on a primitive of `rank` must be nearer than: equal distances go to
    /// the primitive first in the scene's order (the floor's rank is 0).
    #[inline(always)]
    fn limits(&self, rank: u32) -> F {
        let mut limit = self.t_max;
        for i in 0..LANES {
            let t = self.t_max[i];
            // `next_up` of a positive distance: the next float, infinity staying itself.
            let up = if t.is_finite() {
                f32::from_bits(t.to_bits() + 1)
            } else {
                t
            };
            limit[i] = if rank < self.rank[i] { up } else { t };
        }
        limit
    }

    /// Keeps the lanes' hits on a primitive of `rank` (each already nearer than its limit).
    #[inline(always)]
    fn keep(&mut self, rank: u32, found: &M, t: &F, colour: &U) {
        for i in 0..LANES {
            if found[i] {
                self.t_max[i] = t[i];
                self.rank[i] = rank;
                self.colour[i] = colour[i];
                self.hit[i] = true;
            }
        }
    }
}

/// The colour of each lane of `p`, its distance along the ray to what it meets and what that
/// is: [`super`]'s per-ray tracing, eight rays at once.
#[inline(always)]
fn trace_packet(frame: &FrameRays, p: &Packet) -> (U, F, U) {
    let [px, py, c, s] = frame.pose;
    let sectors = frame.sectors;
    let (mut o, mut d) = (p.o, p.d);
    for i in 0..LANES {
        let (ox, oy, dx, dy) = (p.o[0][i], p.o[1][i], p.d[0][i], p.d[1][i]);
        o[0][i] = px + c * ox - s * oy;
        o[1][i] = py + s * ox + c * oy;
        d[0][i] = c * dx - s * dy;
        d[1][i] = s * dx + c * dy;
    }
    // A ray that leaves above everything and does not come down is sky; one that goes down to
    // the floor stops there unless something nearer hides it.
    let (mut sky, mut floor, mut t_max) = ([false; LANES], [false; LANES], [0.0; LANES]);
    for i in 0..LANES {
        sky[i] = d[2][i] >= 0.0 && o[2][i] > sectors.top_mm;
        floor[i] = p.floor_t[i] > 0.0;
        t_max[i] = if floor[i] {
            p.floor_t[i]
        } else {
            f32::INFINITY
        };
    }
    let mut near = Nearest {
        t_max,
        rank: [0; LANES],
        colour: [0; LANES],
        hit: [false; LANES],
    };
    if let Some(b) = frame.body.filter(|_| p.may_meet_body) {
        let rank = sectors.rank(Prim::Cylinder(b as u32));
        let limit = near.limits(rank);
        let (found, t, colour) = hit_cylinder(frame, b, &o, &d, &limit);
        near.keep(rank, &found, &t, &colour);
    }
    // One pass a sector the lanes fall in (almost always one).
    let mut sector = [0usize; LANES];
    for i in 0..LANES {
        sector[i] = (p.azimuth[i].wrapping_add(frame.heading) >> SECTOR_SHIFT) as usize;
    }
    let mut left = sky.map(|s| !s);
    while let Some(first) = left.iter().position(|&l| l) {
        let mut lanes = [false; LANES];
        for i in 0..LANES {
            lanes[i] = left[i] && sector[i] == sector[first];
            left[i] &= !lanes[i];
        }
        trace_sector(frame, sector[first], &lanes, &sky, p, &o, &d, &mut near);
    }
    let paint = floor_paint(frame.scene, &o, &d, &near.t_max);
    let (mut out, mut t, mut code) = ([0; LANES], near.t_max, [0; LANES]);
    for i in 0..LANES {
        let nothing = sky[i] || !(near.hit[i] || floor[i]);
        (out[i], code[i]) = if nothing {
            t[i] = f32::INFINITY;
            (sectors.sky, trace::CODE_SKY)
        } else if near.hit[i] {
            (near.colour[i], near.rank[i])
        } else {
            (
                sectors.palette[paint[i] as usize],
                trace::CODE_FLOOR | paint[i],
            )
        };
    }
    (out, t, code)
}

/// Traces the primitives of `sector` (nearest first) for the packet, until none can be nearer
/// than the hit so far of any of `lanes` (the lanes in that sector).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn trace_sector(
    frame: &FrameRays,
    sector: usize,
    lanes: &M,
    sky: &M,
    p: &Packet,
    o: &[F; 3],
    d: &[F; 3],
    near: &mut Nearest,
) {
    let sectors = frame.sectors;
    let range = sectors.offsets[sector] as usize..sectors.offsets[sector + 1] as usize;
    for item in &sectors.items[range] {
        let (open, needed) = lanes_open(item, lanes, sky, p, near, frame.rho);
        if !open {
            break;
        }
        if !needed {
            continue;
        }
        let rank = sectors.rank(item.prim);
        let limit = near.limits(rank);
        let (found, t, colour) = match item.prim {
            Prim::Box(i) => hit_box(frame, i as usize, o, d, &limit),
            Prim::Quad(i) => hit_quad(frame, i as usize, o, d, &limit),
            Prim::Cylinder(i) => hit_cylinder(frame, i as usize, o, d, &limit),
            Prim::Sphere(i) => hit_sphere(frame, i as usize, o, d, &limit),
        };
        near.keep(rank, &found, &t, &colour);
    }
}

/// Whether any of `lanes` may still meet `item` or a farther primitive nearer than its hit so
/// far (else the sector is done), and whether one may meet `item` itself (else it is passed).
#[inline(always)]
fn lanes_open(
    item: &Item,
    lanes: &M,
    sky: &M,
    p: &Packet,
    near: &Nearest,
    rho: f32,
) -> (bool, bool) {
    let (mut open, mut needed) = (false, false);
    for i in 0..LANES {
        let beyond = item.d_min >= near.t_max[i] * p.d_xy[i] + rho + 1.0;
        let lane_open = lanes[i] && !sky[i] && !beyond;
        open |= lane_open;
        needed |= lane_open && !item.passes_over(p.o[2][i], p.d[2][i], p.d_xy[i]);
    }
    (open, needed)
}

/// [`trace::slab`] over lanes: whether each lane's ray can be in `[lo, hi]` at all, and the
/// interval of `t` where it is.
#[inline(always)]
fn slab(o: &F, d: &F, lo: f32, hi: f32) -> (M, F, F) {
    let (mut ok, mut t0, mut t1) = ([false; LANES], [0.0; LANES], [0.0; LANES]);
    for i in 0..LANES {
        let parallel = d[i].abs() < 1e-12;
        let inv = 1.0 / d[i];
        let ta = (lo - o[i]) * inv;
        let tb = (hi - o[i]) * inv;
        ok[i] = !parallel || !(o[i] < lo || o[i] > hi);
        t0[i] = if parallel {
            f32::NEG_INFINITY
        } else {
            ta.min(tb)
        };
        t1[i] = if parallel { f32::INFINITY } else { ta.max(tb) };
    }
    (ok, t0, t1)
}

/// [`trace::hit_box_face`] over lanes, with the colour of the face hit.
#[inline(always)]
fn hit_box(frame: &FrameRays, k: usize, o: &[F; 3], d: &[F; 3], limit: &F) -> (M, F, U) {
    let b = &frame.scene.boxes[k];
    let [cx, cy, hx, hy] = b.geom;
    let [c, sn, base, top] = b.frame;
    let (mut lo, mut ld) = ([[0.0; LANES]; 2], [[0.0; LANES]; 2]);
    for i in 0..LANES {
        let rx = o[0][i] - cx;
        let ry = o[1][i] - cy;
        lo[0][i] = c * rx + sn * ry;
        lo[1][i] = -sn * rx + c * ry;
        ld[0][i] = c * d[0][i] + sn * d[1][i];
        ld[1][i] = -sn * d[0][i] + c * d[1][i];
    }
    let (okx, x0, x1) = slab(&lo[0], &ld[0], -hx, hx);
    let (oky, y0, y1) = slab(&lo[1], &ld[1], -hy, hy);
    let (okz, z0, z1) = slab(&o[2], &d[2], base, top);
    let (mut found, mut tn, mut face) = ([false; LANES], [0.0; LANES], [0u32; LANES]);
    for i in 0..LANES {
        tn[i] = x0[i].max(y0[i]).max(z0[i]);
        let tf = x1[i].min(y1[i]).min(z1[i]);
        found[i] =
            okx[i] && oky[i] && okz[i] && !(tn[i] > tf || tn[i] <= T_EPS || tn[i] >= limit[i]);
        // The face entered, as [`BoxFace::index`] numbers it: the axis, then 1 where the
        // outward normal is negative (the ray goes along the axis's positive direction).
        let along = |v: f32| u32::from(!v.is_sign_negative());
        face[i] = if tn[i] == x0[i] {
            along(ld[0][i])
        } else if tn[i] == y0[i] {
            2 + along(ld[1][i])
        } else {
            4 + along(d[2][i])
        };
    }
    let mut colour = [0; LANES];
    if b.color[3] < 0.0 {
        let faces = &frame.sectors.box_faces[k];
        for i in 0..LANES {
            colour[i] = faces[(face[i] as usize).min(5)];
        }
    } else {
        for i in 0..LANES {
            if found[i] {
                let f = (lo[0][i] + tn[i] * ld[0][i] + hx) / (2.0 * hx);
                colour[i] = board_colour(frame.scene, b, face[i] as usize, f);
            }
        }
    }
    (found, tn, colour)
}

/// The shaded colour of a striped board's face `face` ([`BoxFace::index`]) at `f` across it,
/// as [`trace::hit_box`] and [`trace::shade`] give it.
fn board_colour(scene: &Scene, b: &BoxPrim, face: usize, f: f32) -> u32 {
    let face = BoxFace::ALL[face.min(5)];
    let mut rgb = [b.color[0], b.color[1], b.color[2]];
    if !matches!(face, BoxFace::X(_)) {
        let board = &scene.boards[b.color[3] as usize];
        let first = board.range[0] as usize;
        let count = board.range[1] as usize;
        let edges = &scene.stripe_edges[first..first + count];
        let k = edges
            .iter()
            .position(|&e| f <= e)
            .unwrap_or(count.saturating_sub(1));
        let col = if k.is_multiple_of(2) {
            board.color_a
        } else {
            board.color_b
        };
        rgb = [col[0], col[1], col[2]];
    }
    let hit = trace::Hit {
        t: 0.0,
        n: face.normal(b),
        rgb,
    };
    trace::pack(trace::shade(scene, &hit))
}

/// [`trace::hit_quad_face`] over lanes, with the colour of the face hit.
#[inline(always)]
fn hit_quad(frame: &FrameRays, k: usize, o: &[F; 3], d: &[F; 3], limit: &F) -> (M, F, U) {
    let q: &QuadPrim = &frame.scene.quads[k];
    let sides = &frame.sectors.quad_sides[k];
    let mut ok = [true; LANES];
    let (mut tn, mut tf) = ([f32::NEG_INFINITY; LANES], [f32::INFINITY; LANES]);
    let mut face = [4u32; LANES];
    for side in 0..4 {
        let (nx, ny, ax, ay) = (
            sides.nx[side],
            sides.ny[side],
            sides.ax[side],
            sides.ay[side],
        );
        for i in 0..LANES {
            let num = nx * (o[0][i] - ax) + ny * (o[1][i] - ay);
            let den = nx * d[0][i] + ny * d[1][i];
            let t = -num / den;
            let bounds = den.abs() >= 1e-12;
            // Parallel to a side and outside it: a miss. Parallel and inside: no bound.
            let outside = !bounds && num > 0.0;
            ok[i] &= !outside;
            let enters = bounds && den < 0.0 && t > tn[i];
            let leaves = bounds && den >= 0.0 && t < tf[i];
            tn[i] = if enters { t } else { tn[i] };
            face[i] = if enters { side as u32 } else { face[i] };
            tf[i] = if leaves { t } else { tf[i] };
        }
    }
    let (okz, z0, z1) = slab(&o[2], &d[2], 0.0, q.z[0]);
    let faces = &frame.sectors.quad_faces[k];
    let (mut found, mut colour) = ([false; LANES], [0; LANES]);
    for i in 0..LANES {
        // Entered through the top going down (-0 counts as down), else the bottom.
        let cap = if d[2][i].is_sign_negative() { 4 } else { 5 };
        let capped = z0[i] > tn[i];
        face[i] = if capped { cap } else { face[i] };
        tn[i] = if capped { z0[i] } else { tn[i] };
        let far = tf[i].min(z1[i]);
        found[i] = ok[i] && okz[i] && !(tn[i] > far || tn[i] <= T_EPS || tn[i] >= limit[i]);
        colour[i] = faces[(face[i] as usize).min(5)];
    }
    (found, tn, colour)
}

/// [`trace::hit_cylinder`] over lanes, with the shaded colour of what is hit (side or top).
#[inline(always)]
fn hit_cylinder(frame: &FrameRays, k: usize, o: &[F; 3], d: &[F; 3], limit: &F) -> (M, F, U) {
    let cyl: &CylinderPrim = &frame.scene.cylinders[k];
    let [cx, cy, r, top] = cyl.geom;
    let top_colour = frame.sectors.cylinder_tops[k];
    let (mut found, mut t_hit, mut colour) = ([false; LANES], [0.0; LANES], [0; LANES]);
    let (mut sides, mut normal) = ([false; LANES], [[0.0; LANES]; 2]);
    for i in 0..LANES {
        let (dx, dy, dz) = (d[0][i], d[1][i], d[2][i]);
        let mx = o[0][i] - cx;
        let my = o[1][i] - cy;
        let a = dx * dx + dy * dy;
        let b = mx * dx + my * dy;
        let c = mx * mx + my * my - r * r;
        let disc = b * b - a * c;
        let t = (-b - disc.sqrt()) / a;
        let z = o[2][i] + t * dz;
        let side = a > 1e-12 && disc >= 0.0 && t > T_EPS && t < limit[i] && z >= 0.0 && z <= top;
        let t_lim = if side { t } else { limit[i] };
        let tt = (top - o[2][i]) / dz;
        let px = mx + tt * dx;
        let py = my + tt * dy;
        let cap =
            dz < 0.0 && o[2][i] > top && tt > T_EPS && tt < t_lim && px * px + py * py <= r * r;
        found[i] = side || cap;
        t_hit[i] = if cap { tt } else { t };
        colour[i] = top_colour;
        sides[i] = side && !cap;
        normal[0][i] = (mx + t * dx) / r;
        normal[1][i] = (my + t * dy) / r;
    }
    // The side's shading, Lambert with the normal at the hit, where the side is hit.
    for i in (0..LANES).filter(|&i| sides[i]) {
        let hit = trace::Hit {
            t: t_hit[i],
            n: [normal[0][i], normal[1][i], 0.0],
            rgb: [cyl.color[0], cyl.color[1], cyl.color[2]],
        };
        colour[i] = trace::pack(trace::shade(frame.scene, &hit));
    }
    (found, t_hit, colour)
}

/// [`trace::hit_sphere`] over lanes (with [`trace::sphere_crossing`]'s steps), with the shaded
/// colour at the hit.
#[inline(always)]
fn hit_sphere(frame: &FrameRays, k: usize, o: &[F; 3], d: &[F; 3], limit: &F) -> (M, F, U) {
    let sp: &SpherePrim = &frame.scene.spheres[k];
    let [cx, cy, cz, r] = sp.geom;
    let (mut found, mut t_hit, mut colour) = ([false; LANES], [0.0; LANES], [0; LANES]);
    let mut normal = [[0.0; LANES]; 3];
    for i in 0..LANES {
        let (dx, dy, dz) = (d[0][i], d[1][i], d[2][i]);
        let mx = o[0][i] - cx;
        let my = o[1][i] - cy;
        let mz = o[2][i] - cz;
        let b = mx * dx + my * dy + mz * dz;
        let fx = mx - b * dx;
        let fy = my - b * dy;
        let fz = mz - b * dz;
        let disc = r * r - (fx * fx + fy * fy + fz * fz);
        let sq = disc.sqrt();
        let t0 = -b - sq;
        let t1 = -b + sq;
        let t = if t0 > T_EPS { t0 } else { t1 };
        found[i] = disc >= 0.0 && t > T_EPS && t < limit[i];
        t_hit[i] = t;
        normal[0][i] = (mx + t * dx) / r;
        normal[1][i] = (my + t * dy) / r;
        normal[2][i] = (mz + t * dz) / r;
    }
    // Lambert with the normal at the hit, where the sphere is hit.
    for i in (0..LANES).filter(|&i| found[i]) {
        let hit = trace::Hit {
            t: t_hit[i],
            n: [normal[0][i], normal[1][i], normal[2][i]],
            rgb: [sp.color[0], sp.color[1], sp.color[2]],
        };
        colour[i] = trace::pack(trace::shade(frame.scene, &hit));
    }
    (found, t_hit, colour)
}

/// [`trace::floor_paint`] over lanes at each ray's floor point (`t` along it): the index of
/// its shaded colour in [`Sectors::palette`] (a lane that meets no floor gets an index too, of
/// no meaning).
#[inline(always)]
fn floor_paint(scene: &Scene, o: &[F; 3], d: &[F; 3], t: &F) -> U {
    let g = &scene.globals;
    let (mut x, mut y) = ([0.0; LANES], [0.0; LANES]);
    for i in 0..LANES {
        x[i] = o[0][i] + t[i] * d[0][i];
        y[i] = o[1][i] + t[i] * d[1][i];
    }
    let mut inside = [g.flags[1] == 0; LANES];
    let mut mark = [u32::MAX; LANES];
    for (k, r) in scene.floor_rects.iter().enumerate() {
        let region = r.frame[2] == FLOOR_REGION;
        let square = r.frame[2] == SQUARE_MARK;
        for i in 0..LANES {
            let dx = x[i] - r.geom[0];
            let dy = y[i] - r.geom[1];
            let lx = r.frame[0] * dx + r.frame[1] * dy;
            let ly = -r.frame[1] * dx + r.frame[0] * dy;
            let in_rect = (lx.abs() <= r.geom[2]) & (ly.abs() <= r.geom[3]);
            let round = lx * lx + ly * ly <= r.geom[2] * r.geom[2];
            let covered = !region && if square { in_rect } else { round };
            inside[i] |= region & in_rect;
            mark[i] = if covered { k as u32 } else { mark[i] };
        }
    }
    let n = scene.floor_rects.len() as u32;
    let [a1, b, w, cr] = g.field;
    let [front, front_in, side, side_in] = g.field2;
    let lines = g.flags[0] != 0;
    let mut paint = [0; LANES];
    for i in 0..LANES {
        let ax = x[i].abs();
        let ay = y[i].abs();
        let boundary = ax >= a1 - w || ay >= b - w;
        let centre = ax <= 0.5 * w;
        let circle = ((x[i] * x[i] + y[i] * y[i]).sqrt() - cr).abs() <= 0.5 * w;
        let defense = ax >= front && ay <= side && (ax <= front_in || ay >= side_in);
        let line = lines && ax <= a1 && ay <= b && (boundary || centre || circle || defense);
        paint[i] = if mark[i] != u32::MAX {
            mark[i]
        } else if !inside[i] {
            n
        } else if line {
            n + 1
        } else {
            n + 2
        };
    }
    paint
}
