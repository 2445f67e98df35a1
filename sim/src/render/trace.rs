//! The scene half of the tracer in `f32`, written to match `trace.wgsl` operation for
//! operation: floor colouring, box, quad, cylinder, sphere and floor intersections, stripe lookup,
//! shading and packing. The CPU renderer calls these; the GPU runs the WGSL twin.

use super::scene::{
    BoxPrim, CylinderPrim, FLOOR_REGION, QuadPrim, RANKED, SQUARE_MARK, Scene, SceneList,
    SpherePrim,
};

/// A 3-vector in `f32`.
pub type V3 = [f32; 3];

/// Hits closer than this (mm) are ignored (the ray's own surface).
pub const T_EPS: f32 = 1e-3;

fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// What a ray hit: distance, normal and colour (before shading).
#[derive(Debug, Clone, Copy)]
pub struct Hit {
    /// Ray parameter.
    pub t: f32,
    /// Unit normal.
    pub n: V3,
    /// Surface colour.
    pub rgb: V3,
}

/// What covers the floor at a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FloorPaint {
    /// A mark painted on the floor (index into `Scene::floor_rects`).
    Mark(usize),
    /// Outside every floor region.
    Outside,
    /// A field line.
    Line,
    /// The bare floor.
    Floor,
}

/// What covers the floor at `(x, y)`: a mark painted on it (the last that covers the point),
/// floor region, field lines (outer lines, halfway line, centre circle, defense areas) or
/// outside.
#[inline]
pub fn floor_paint(s: &Scene, x: f32, y: f32) -> FloorPaint {
    let g = &s.globals;
    let mut inside = g.flags[1] == 0;
    let mut mark = None;
    for (i, r) in s.floor_rects.iter().enumerate() {
        let dx = x - r.geom[0];
        let dy = y - r.geom[1];
        let lx = r.frame[0] * dx + r.frame[1] * dy;
        let ly = -r.frame[1] * dx + r.frame[0] * dy;
        // `&`, not `&&`: both tests are cheap, and a branch on them would be a coin toss.
        let in_rect = (lx.abs() <= r.geom[2]) & (ly.abs() <= r.geom[3]);
        if r.frame[2] == FLOOR_REGION {
            inside |= in_rect;
        } else {
            let covered = if r.frame[2] == SQUARE_MARK {
                in_rect
            } else {
                lx * lx + ly * ly <= r.geom[2] * r.geom[2]
            };
            mark = if covered { Some(i) } else { mark };
        }
    }
    if let Some(m) = mark {
        return FloorPaint::Mark(m);
    }
    if !inside {
        return FloorPaint::Outside;
    }
    if g.flags[0] != 0 {
        let ax = x.abs();
        let ay = y.abs();
        let [a1, b, w, cr] = g.field;
        let [front, front_in, side, side_in] = g.field2;
        if ax <= a1 && ay <= b {
            let boundary = ax >= a1 - w || ay >= b - w;
            let centre = ax <= 0.5 * w;
            let circle = ((x * x + y * y).sqrt() - cr).abs() <= 0.5 * w;
            let defense = ax >= front && ay <= side && (ax <= front_in || ay >= side_in);
            if boundary || centre || circle || defense {
                return FloorPaint::Line;
            }
        }
    }
    FloorPaint::Floor
}

/// The colour of a floor paint.
pub fn paint_color(s: &Scene, paint: FloorPaint) -> V3 {
    let g = &s.globals;
    let c = match paint {
        FloorPaint::Mark(i) => s.floor_rects[i].color,
        FloorPaint::Outside => g.outside_rgb,
        FloorPaint::Line => g.line_rgb,
        FloorPaint::Floor => g.floor_rgb,
    };
    [c[0], c[1], c[2]]
}

/// Colour of the floor at `(x, y)` ([`floor_paint`]'s colour).
pub fn floor_color(s: &Scene, x: f32, y: f32) -> V3 {
    paint_color(s, floor_paint(s, x, y))
}

/// The distance along the ray to the floor, if it goes down to it.
pub fn floor_t(o: V3, d: V3) -> Option<f32> {
    if d[2] >= 0.0 {
        return None;
    }
    let t = -o[2] / d[2];
    (t > T_EPS).then_some(t)
}

/// The normal of the floor.
pub const FLOOR_NORMAL: V3 = [0.0, 0.0, 1.0];

/// Slab interval of `o + t d` in `[lo, hi]`; `None` when parallel and outside.
fn slab(o: f32, d: f32, lo: f32, hi: f32) -> Option<(f32, f32)> {
    if d.abs() < 1e-12 {
        if o < lo || o > hi {
            return None;
        }
        return Some((f32::NEG_INFINITY, f32::INFINITY));
    }
    let inv = 1.0 / d;
    let ta = (lo - o) * inv;
    let tb = (hi - o) * inv;
    Some((ta.min(tb), ta.max(tb)))
}

/// Entry of the ray into a box, if before `t_max`.
pub fn hit_box(s: &Scene, b: &BoxPrim, o: V3, d: V3, t_max: f32) -> Option<Hit> {
    let (tn, face, f) = hit_box_face(b, o, d, t_max)?;
    let mut rgb = [b.color[0], b.color[1], b.color[2]];
    if b.color[3] >= 0.0 && !matches!(face, BoxFace::X(_)) {
        let board = &s.boards[b.color[3] as usize];
        let first = board.range[0] as usize;
        let count = board.range[1] as usize;
        let mut k = count.saturating_sub(1);
        for i in 0..count {
            if f <= s.stripe_edges[first + i] {
                k = i;
                break;
            }
        }
        let col = if k.is_multiple_of(2) {
            board.color_a
        } else {
            board.color_b
        };
        rgb = [col[0], col[1], col[2]];
    }
    Some(Hit {
        t: tn,
        n: face.normal(b),
        rgb,
    })
}

/// The face of a box a ray enters by: across its local x or y extent or its height, with the
/// sign (+1 or -1) of the outward normal along that axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BoxFace {
    /// A face across the box's local x.
    X(f32),
    /// A face across its local y.
    Y(f32),
    /// Its top (+1) or bottom (-1).
    Z(f32),
}

impl BoxFace {
    /// Every face, in the order of [`BoxFace::index`].
    pub const ALL: [BoxFace; 6] = [
        BoxFace::X(1.0),
        BoxFace::X(-1.0),
        BoxFace::Y(1.0),
        BoxFace::Y(-1.0),
        BoxFace::Z(1.0),
        BoxFace::Z(-1.0),
    ];

    /// Its outward unit normal (world frame) on box `b`.
    pub fn normal(self, b: &BoxPrim) -> V3 {
        let [c, sn, _, _] = b.frame;
        match self {
            BoxFace::X(nx) => [c * nx, sn * nx, 0.0],
            BoxFace::Y(ny) => [-sn * ny, c * ny, 0.0],
            BoxFace::Z(nz) => [0.0, 0.0, nz],
        }
    }

    /// A small index: 0-5 in the order of [`BoxFace::ALL`].
    pub fn index(self) -> usize {
        let (axis, sign) = match self {
            BoxFace::X(s) => (0, s),
            BoxFace::Y(s) => (2, s),
            BoxFace::Z(s) => (4, s),
        };
        axis + usize::from(sign < 0.0)
    }
}

/// [`hit_box`]'s distance, the face entered and the entry point's place across the box's local
/// x as a fraction of its length (a board's stripe coordinate), without the colour.
#[inline]
pub fn hit_box_face(b: &BoxPrim, o: V3, d: V3, t_max: f32) -> Option<(f32, BoxFace, f32)> {
    let [cx, cy, hx, hy] = b.geom;
    let [c, sn, base, top] = b.frame;
    let rx = o[0] - cx;
    let ry = o[1] - cy;
    let lox = c * rx + sn * ry;
    let loy = -sn * rx + c * ry;
    let ldx = c * d[0] + sn * d[1];
    let ldy = -sn * d[0] + c * d[1];
    let (x0, x1) = slab(lox, ldx, -hx, hx)?;
    let (y0, y1) = slab(loy, ldy, -hy, hy)?;
    let (z0, z1) = slab(o[2], d[2], base, top)?;
    let tn = x0.max(y0).max(z0);
    let tf = x1.min(y1).min(z1);
    if tn > tf || tn <= T_EPS || tn >= t_max {
        return None;
    }
    // The outward normal is against the ray: -sign(d) along the axis entered.
    let against = |v: f32| if v.is_sign_negative() { 1.0 } else { -1.0 };
    let face = if tn == x0 {
        BoxFace::X(against(ldx))
    } else if tn == y0 {
        BoxFace::Y(against(ldy))
    } else {
        BoxFace::Z(against(d[2]))
    };
    let f = (lox + tn * ldx + hx) / (2.0 * hx);
    Some((tn, face, f))
}

/// The sides of a quadrilateral prism, prepared once a frame: each side's outward unit normal
/// and its first corner, as four lanes of each (a side too short to have a normal is all
/// zeros, which every ray finds parallel and inside: as if it were not there).
#[derive(Debug, Clone, Copy, Default)]
pub struct QuadSides {
    /// Normals' x.
    pub nx: [f32; 4],
    /// Normals' y.
    pub ny: [f32; 4],
    /// First corners' x.
    pub ax: [f32; 4],
    /// First corners' y.
    pub ay: [f32; 4],
}

/// The sides of `q` (counter-clockwise corners).
pub fn quad_sides(q: &QuadPrim) -> QuadSides {
    let mut sides = QuadSides::default();
    for i in 0..4 {
        let a = q.corner(i);
        let b = q.corner((i + 1) % 4);
        let ex = b[0] - a[0];
        let ey = b[1] - a[1];
        let len = (ex * ex + ey * ey).sqrt();
        if len < 1e-6 {
            continue;
        }
        // Outward normal of a counter-clockwise side.
        sides.nx[i] = ey / len;
        sides.ny[i] = -ex / len;
        sides.ax[i] = a[0];
        sides.ay[i] = a[1];
    }
    sides
}

/// Entry of the ray into a quadrilateral prism (Cyrus-Beck over its sides, then the slab from
/// the floor to its top), if before `t_max`.
pub fn hit_quad(q: &QuadPrim, o: V3, d: V3, t_max: f32) -> Option<Hit> {
    hit_quad_sides(q, &quad_sides(q), o, d, t_max)
}

/// [`hit_quad`] with the prism's sides prepared ([`quad_sides`]): the same operations, so the
/// same result to the bit.
pub fn hit_quad_sides(q: &QuadPrim, sides: &QuadSides, o: V3, d: V3, t_max: f32) -> Option<Hit> {
    let (t, face) = hit_quad_face(q, sides, o, d, t_max)?;
    Some(Hit {
        t,
        n: face.normal(sides),
        rgb: [q.color[0], q.color[1], q.color[2]],
    })
}

/// The face of a quadrilateral prism a ray enters by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum QuadFace {
    /// Side `i` (from corner `i` to corner `i + 1`).
    Side(usize),
    /// The top, entered going down (normal +z).
    Top,
    /// The bottom, entered going up (normal -z).
    Bottom,
}

impl QuadFace {
    /// Every face, in the order of [`QuadFace::index`].
    pub const ALL: [QuadFace; 6] = [
        QuadFace::Side(0),
        QuadFace::Side(1),
        QuadFace::Side(2),
        QuadFace::Side(3),
        QuadFace::Top,
        QuadFace::Bottom,
    ];

    /// Its outward unit normal.
    pub fn normal(self, sides: &QuadSides) -> V3 {
        match self {
            QuadFace::Side(i) => [sides.nx[i], sides.ny[i], 0.0],
            QuadFace::Top => [0.0, 0.0, 1.0],
            QuadFace::Bottom => [0.0, 0.0, -1.0],
        }
    }

    /// A small index: sides 0-3, top 4, bottom 5.
    pub fn index(self) -> usize {
        match self {
            QuadFace::Side(i) => i,
            QuadFace::Top => 4,
            QuadFace::Bottom => 5,
        }
    }
}

/// [`hit_quad_sides`]'s distance and the face entered, without the colour.
#[inline]
pub fn hit_quad_face(
    q: &QuadPrim,
    sides: &QuadSides,
    o: V3,
    d: V3,
    t_max: f32,
) -> Option<(f32, QuadFace)> {
    // The four sides' numerators, denominators and crossings, lane by lane.
    let (mut num, mut den, mut t) = ([0.0f32; 4], [0.0f32; 4], [0.0f32; 4]);
    for i in 0..4 {
        num[i] = sides.nx[i] * (o[0] - sides.ax[i]) + sides.ny[i] * (o[1] - sides.ay[i]);
        den[i] = sides.nx[i] * d[0] + sides.ny[i] * d[1];
        t[i] = -num[i] / den[i];
    }
    // Parallel to a side and outside it: a miss. Parallel and inside: that side does not bound.
    if (0..4).any(|i| den[i].abs() < 1e-12 && num[i] > 0.0) {
        return None;
    }
    // The latest entry and the earliest exit, taken in side order (selects, not branches).
    let mut tn = f32::NEG_INFINITY;
    let mut tf = f32::INFINITY;
    let mut side = usize::MAX;
    for i in 0..4 {
        let bounds = den[i].abs() >= 1e-12;
        let enters = bounds && den[i] < 0.0 && t[i] > tn;
        let leaves = bounds && den[i] >= 0.0 && t[i] < tf;
        tn = if enters { t[i] } else { tn };
        side = if enters { i } else { side };
        tf = if leaves { t[i] } else { tf };
    }
    let mut face = if side < 4 {
        QuadFace::Side(side)
    } else {
        QuadFace::Top
    };
    let (z0, z1) = slab(o[2], d[2], 0.0, q.z[0])?;
    if z0 > tn {
        tn = z0;
        // The normal -sign(d_z) z: -0 counts as going down, +0 as going up.
        face = if d[2].is_sign_negative() {
            QuadFace::Top
        } else {
            QuadFace::Bottom
        };
    }
    tf = tf.min(z1);
    if tn > tf || tn <= T_EPS || tn >= t_max {
        return None;
    }
    Some((tn, face))
}

/// Entry of the ray into an upright cylinder (side or top), if before `t_max`.
#[inline]
pub fn hit_cylinder(cy: &CylinderPrim, o: V3, d: V3, t_max: f32) -> Option<Hit> {
    let [cx, cyy, r, top] = cy.geom;
    let mx = o[0] - cx;
    let my = o[1] - cyy;
    let mut best: Option<Hit> = None;
    let mut t_lim = t_max;
    let a = d[0] * d[0] + d[1] * d[1];
    if a > 1e-12 {
        let b = mx * d[0] + my * d[1];
        let c = mx * mx + my * my - r * r;
        let disc = b * b - a * c;
        if disc >= 0.0 {
            let t = (-b - disc.sqrt()) / a;
            let z = o[2] + t * d[2];
            if t > T_EPS && t < t_lim && z >= 0.0 && z <= top {
                t_lim = t;
                best = Some(Hit {
                    t,
                    n: [(mx + t * d[0]) / r, (my + t * d[1]) / r, 0.0],
                    rgb: [cy.color[0], cy.color[1], cy.color[2]],
                });
            }
        }
    }
    if d[2] < 0.0 && o[2] > top {
        let t = (top - o[2]) / d[2];
        let px = mx + t * d[0];
        let py = my + t * d[1];
        if t > T_EPS && t < t_lim && px * px + py * py <= r * r {
            best = Some(Hit {
                t,
                n: [0.0, 0.0, 1.0],
                rgb: [cy.top[0], cy.top[1], cy.top[2]],
            });
        }
    }
    best
}

/// Where the unit ray `o + t d` crosses a sphere: the offset `m = o - centre` and, where it
/// crosses at all, the distances `(t0, t1)` of its entry and exit (`t0 <= t1`).
///
/// The discriminant is taken as `r^2 - |m - (m . d) d|^2` (the radius squared less the squared
/// distance of the line from the centre), not as `(m . d)^2 - (|m|^2 - r^2)`, whose two large
/// terms cancel in `f32` for a small sphere far off (4 m away, each is some 1.6e7 mm^2 and
/// rounds by 1 or 2, against a 43 mm ball's 462 mm^2).
#[inline]
pub fn sphere_crossing(sp: &SpherePrim, o: V3, d: V3) -> (V3, Option<(f32, f32)>) {
    let [cx, cy, cz, r] = sp.geom;
    let m = [o[0] - cx, o[1] - cy, o[2] - cz];
    let b = m[0] * d[0] + m[1] * d[1] + m[2] * d[2];
    let fx = m[0] - b * d[0];
    let fy = m[1] - b * d[1];
    let fz = m[2] - b * d[2];
    let disc = r * r - (fx * fx + fy * fy + fz * fz);
    if disc < 0.0 {
        return (m, None);
    }
    let sq = disc.sqrt();
    (m, Some((-b - sq, -b + sq)))
}

/// The first crossing of a sphere beyond [`T_EPS`] (its entry, or its exit for a ray that starts
/// inside), if before `t_max`, with the outward normal there.
#[inline]
pub fn hit_sphere(sp: &SpherePrim, o: V3, d: V3, t_max: f32) -> Option<Hit> {
    let (m, crossing) = sphere_crossing(sp, o, d);
    let (t0, t1) = crossing?;
    let t = if t0 > T_EPS { t0 } else { t1 };
    if !(t > T_EPS && t < t_max) {
        return None;
    }
    let r = sp.geom[3];
    Some(Hit {
        t,
        n: [
            (m[0] + t * d[0]) / r,
            (m[1] + t * d[1]) / r,
            (m[2] + t * d[2]) / r,
        ],
        rgb: [sp.color[0], sp.color[1], sp.color[2]],
    })
}

/// The floor hit, if the ray goes down.
pub fn hit_floor(s: &Scene, o: V3, d: V3) -> Option<Hit> {
    let t = floor_t(o, d)?;
    let x = o[0] + t * d[0];
    let y = o[1] + t * d[1];
    Some(Hit {
        t,
        n: FLOOR_NORMAL,
        rgb: floor_color(s, x, y),
    })
}

/// Lambert shading normalised so that the floor shows its own colour.
pub fn shade(s: &Scene, h: &Hit) -> V3 {
    let g = &s.globals;
    let l = [g.light[0], g.light[1], g.light[2]];
    let k = (g.light[3] + g.light2[0] * dot(h.n, l).max(0.0)) * g.light2[1];
    [h.rgb[0] * k, h.rgb[1] * k, h.rgb[2] * k]
}

/// Packs a colour into RGBA8 (alpha 255), rounding to the nearest level.
pub fn pack(c: V3) -> u32 {
    let q = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u32;
    q(c[0]) | (q(c[1]) << 8) | (q(c[2]) << 16) | (255 << 24)
}

/// What a ray shows, as a number: a primitive's rank in the scene's order (boxes from 1, then
/// quad prisms, then cylinders, then spheres), [`CODE_FLOOR`] with the floor paint's index
/// ([`paint_index`]), or [`CODE_SKY`].
pub type Code = u32;

/// [`Code`] of a ray that meets nothing.
pub const CODE_SKY: Code = u32::MAX;

/// [`Code`] of a pixel that sees no mirror.
pub const CODE_NOTHING: Code = u32::MAX - 1;

/// [`Code`] of the floor: this bit with the paint's index below it.
pub const CODE_FLOOR: Code = 1 << 31;

/// The index of a floor paint among the floor's colours: mark `i` is `i`, then outside the
/// region, a line and the bare floor (the CPU renderer's palette order).
pub fn paint_index(s: &Scene, paint: FloorPaint) -> u32 {
    let n = s.floor_rects.len() as u32;
    match paint {
        FloorPaint::Mark(i) => i as u32,
        FloorPaint::Outside => n,
        FloorPaint::Line => n + 1,
        FloorPaint::Floor => n + 2,
    }
}

/// The floor paint of index `k` ([`paint_index`]'s inverse).
pub fn paint_of_index(s: &Scene, k: u32) -> FloorPaint {
    let n = s.floor_rects.len() as u32;
    match k.checked_sub(n) {
        None => FloorPaint::Mark(k as usize),
        Some(0) => FloorPaint::Outside,
        Some(1) => FloorPaint::Line,
        Some(_) => FloorPaint::Floor,
    }
}

/// A world ray traced against every primitive: its packed colour, the distance along it to
/// what it meets (infinity for the sky) and what that is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Traced {
    /// Packed RGBA8.
    pub colour: u32,
    /// Distance along the (unit) ray, mm.
    pub t: f32,
    /// What it meets.
    pub code: Code,
}

/// [`trace_all`] with the distance and what the ray meets.
pub fn trace_ray(s: &Scene, o: V3, d: V3) -> Traced {
    let mut best = hit_floor(s, o, d);
    let mut code = best.map_or(CODE_SKY, |h| {
        let paint = floor_paint(s, o[0] + h.t * d[0], o[1] + h.t * d[1]);
        CODE_FLOOR | paint_index(s, paint)
    });
    let mut t_max = best.map_or(f32::INFINITY, |h| h.t);
    let mut rank = 1;
    let mut keep = |hit: Option<Hit>, t_max: &mut f32, best: &mut Option<Hit>, rank: &mut u32| {
        if let Some(h) = hit {
            *t_max = h.t;
            *best = Some(h);
            code = *rank;
        }
        *rank += 1;
    };
    // Each list in the order of the ranks, so that a primitive's code is its rank.
    for list in RANKED {
        match list {
            SceneList::Boxes => {
                for b in &s.boxes {
                    keep(hit_box(s, b, o, d, t_max), &mut t_max, &mut best, &mut rank);
                }
            }
            SceneList::Quads => {
                for q in &s.quads {
                    keep(hit_quad(q, o, d, t_max), &mut t_max, &mut best, &mut rank);
                }
            }
            SceneList::Cylinders => {
                for c in &s.cylinders {
                    let hit = hit_cylinder(c, o, d, t_max);
                    keep(hit, &mut t_max, &mut best, &mut rank);
                }
            }
            SceneList::Spheres => {
                for sp in &s.spheres {
                    keep(
                        hit_sphere(sp, o, d, t_max),
                        &mut t_max,
                        &mut best,
                        &mut rank,
                    );
                }
            }
            _ => {}
        }
    }
    let colour = match best {
        Some(h) => pack(shade(s, &h)),
        None => pack([
            s.globals.sky_rgb[0],
            s.globals.sky_rgb[1],
            s.globals.sky_rgb[2],
        ]),
    };
    Traced {
        colour,
        t: t_max,
        code,
    }
}

/// The colour of a world ray traced against every primitive (the reference the culled CPU
/// path and the GPU must agree with).
pub fn trace_all(s: &Scene, o: V3, d: V3) -> u32 {
    trace_ray(s, o, d).colour
}

/// The packed value of a pixel that sees no mirror.
pub const BLACK: u32 = 255 << 24;
