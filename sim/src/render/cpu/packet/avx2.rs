//! The packet tracer in AVX2 intrinsics: [`super`]'s lanes, one 256-bit register each.
//!
//! Each step is the lane code's (and so the scalar tracer's) operation for operation, with no
//! fused multiply-add: the same roundings, the same colours. Comparisons are the ordered ones
//! Rust's `<`, `>=`, ... are (false where a side is NaN), a negated comparison is the
//! comparison's complement, and `min`/`max` are taken only where neither side can be NaN (where
//! `_mm256_min_ps` and `f32::min` agree).

use super::{FrameRays, LANES, Outputs, Packet, U};
use crate::render::cpu::{Item, Prim, SECTOR_SHIFT};
use crate::render::scene::{FLOOR_REGION, SQUARE_MARK, Scene};
use crate::render::trace::{CODE_FLOOR, CODE_SKY, T_EPS};
use std::arch::x86_64::*;

type V = __m256;
type I = __m256i;

/// Traces `packets` as [`super::trace_chunk`] does.
#[target_feature(enable = "avx2")]
pub(super) fn trace_chunk(frame: &FrameRays, packets: &[Packet], out: &Outputs) {
    let with_truth = out.truth.is_some();
    for p in packets {
        let (colours, truth) = trace_packet(frame, p, with_truth);
        // SAFETY: as in `super::trace_chunk`: this chunk alone writes these pixels.
        unsafe { out.colour.write(p, &lanes_u(colours)) };
        if let (Some((ts, codes)), Some((t, code))) = (&out.truth, truth) {
            // SAFETY: as above.
            unsafe {
                ts.write(p, &lanes_f(t));
                codes.write(p, &lanes_u(code));
            }
        }
    }
}

#[inline]
#[target_feature(enable = "avx2")]
fn load(a: &[f32; LANES]) -> V {
    // SAFETY: eight floats are read from an array of eight.
    unsafe { _mm256_loadu_ps(a.as_ptr()) }
}

#[inline]
#[target_feature(enable = "avx2")]
fn load_u(a: &U) -> I {
    // SAFETY: eight 32-bit lanes are read from an array of eight.
    unsafe { _mm256_loadu_si256(a.as_ptr().cast()) }
}

#[inline]
#[target_feature(enable = "avx2")]
fn lanes_f(v: V) -> [f32; LANES] {
    let mut a = [0.0; LANES];
    // SAFETY: eight floats are written to an array of eight.
    unsafe { _mm256_storeu_ps(a.as_mut_ptr(), v) };
    a
}

#[inline]
#[target_feature(enable = "avx2")]
fn lanes_u(v: I) -> U {
    let mut a = [0; LANES];
    // SAFETY: eight 32-bit lanes are written to an array of eight.
    unsafe { _mm256_storeu_si256(a.as_mut_ptr().cast(), v) };
    a
}

#[inline]
#[target_feature(enable = "avx2")]
fn splat(x: f32) -> V {
    _mm256_set1_ps(x)
}

#[inline]
#[target_feature(enable = "avx2")]
fn splat_u(x: u32) -> I {
    _mm256_set1_epi32(x as i32)
}

#[inline]
#[target_feature(enable = "avx2")]
fn add(a: V, b: V) -> V {
    _mm256_add_ps(a, b)
}

#[inline]
#[target_feature(enable = "avx2")]
fn sub(a: V, b: V) -> V {
    _mm256_sub_ps(a, b)
}

#[inline]
#[target_feature(enable = "avx2")]
fn mul(a: V, b: V) -> V {
    _mm256_mul_ps(a, b)
}

#[inline]
#[target_feature(enable = "avx2")]
fn div(a: V, b: V) -> V {
    _mm256_div_ps(a, b)
}

/// `-a`: the sign flipped, as Rust's negation.
#[inline]
#[target_feature(enable = "avx2")]
fn neg(a: V) -> V {
    _mm256_xor_ps(a, splat(-0.0))
}

#[inline]
#[target_feature(enable = "avx2")]
fn abs(a: V) -> V {
    _mm256_andnot_ps(splat(-0.0), a)
}

#[inline]
#[target_feature(enable = "avx2")]
fn and(a: V, b: V) -> V {
    _mm256_and_ps(a, b)
}

#[inline]
#[target_feature(enable = "avx2")]
fn or(a: V, b: V) -> V {
    _mm256_or_ps(a, b)
}

#[inline]
#[target_feature(enable = "avx2")]
fn not(a: V) -> V {
    _mm256_xor_ps(a, _mm256_castsi256_ps(_mm256_set1_epi32(-1)))
}

/// `a` where `m`, else `b`.
#[inline]
#[target_feature(enable = "avx2")]
fn select(m: V, a: V, b: V) -> V {
    _mm256_blendv_ps(b, a, m)
}

/// `a` where `m`, else `b`, in integer lanes.
#[inline]
#[target_feature(enable = "avx2")]
fn select_u(m: V, a: I, b: I) -> I {
    _mm256_blendv_epi8(b, a, _mm256_castps_si256(m))
}

#[inline]
#[target_feature(enable = "avx2")]
fn any(m: V) -> bool {
    _mm256_movemask_ps(m) != 0
}

#[inline]
#[target_feature(enable = "avx2")]
fn lt(a: V, b: V) -> V {
    _mm256_cmp_ps::<_CMP_LT_OQ>(a, b)
}

#[inline]
#[target_feature(enable = "avx2")]
fn le(a: V, b: V) -> V {
    _mm256_cmp_ps::<_CMP_LE_OQ>(a, b)
}

#[inline]
#[target_feature(enable = "avx2")]
fn gt(a: V, b: V) -> V {
    _mm256_cmp_ps::<_CMP_GT_OQ>(a, b)
}

#[inline]
#[target_feature(enable = "avx2")]
fn ge(a: V, b: V) -> V {
    _mm256_cmp_ps::<_CMP_GE_OQ>(a, b)
}

#[inline]
#[target_feature(enable = "avx2")]
fn eq(a: V, b: V) -> V {
    _mm256_cmp_ps::<_CMP_EQ_OQ>(a, b)
}

/// `f32::is_sign_negative` as a mask.
#[inline]
#[target_feature(enable = "avx2")]
fn sign_negative(a: V) -> V {
    _mm256_castsi256_ps(_mm256_srai_epi32::<31>(_mm256_castps_si256(a)))
}

/// A mask where every lane is `b`.
#[inline]
#[target_feature(enable = "avx2")]
fn mask(b: bool) -> V {
    _mm256_castsi256_ps(_mm256_set1_epi32(-i32::from(b)))
}

/// The world rays of a packet.
#[derive(Clone, Copy)]
struct Rays {
    o: [V; 3],
    d: [V; 3],
    d_xy: V,
    /// `1 / d_z`.
    inv_dz: V,
}

/// The nearest hit of each lane so far (as [`super::Nearest`]).
#[derive(Clone, Copy)]
struct Nearest {
    t_max: V,
    rank: I,
    colour: I,
    hit: V,
}

impl Nearest {
    #[inline]
    #[target_feature(enable = "avx2")]
    fn limits(&self, rank: u32) -> V {
        let t = self.t_max;
        let up = _mm256_castsi256_ps(_mm256_add_epi32(_mm256_castps_si256(t), splat_u(1)));
        let up = select(lt(abs(t), splat(f32::INFINITY)), up, t);
        let below = _mm256_castsi256_ps(_mm256_cmpgt_epi32(self.rank, splat_u(rank)));
        select(below, up, t)
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    fn keep(&mut self, rank: u32, found: V, t: V, colour: I) {
        self.t_max = select(found, t, self.t_max);
        self.rank = select_u(found, splat_u(rank), self.rank);
        self.colour = select_u(found, colour, self.colour);
        self.hit = or(self.hit, found);
    }
}

/// The colour of each lane and, `with_truth`, its distance along the ray to what it meets and
/// what that is.
#[inline]
#[target_feature(enable = "avx2")]
fn trace_packet(frame: &FrameRays, p: &Packet, with_truth: bool) -> (I, Option<(V, I)>) {
    let [px, py, c, s] = frame.pose;
    let (px, py, c, s) = (splat(px), splat(py), splat(c), splat(s));
    let sectors = frame.sectors;
    let (ox, oy, oz) = (load(&p.o[0]), load(&p.o[1]), load(&p.o[2]));
    let (dx, dy, dz) = (load(&p.d[0]), load(&p.d[1]), load(&p.d[2]));
    let r = Rays {
        o: [
            sub(add(px, mul(c, ox)), mul(s, oy)),
            add(add(py, mul(s, ox)), mul(c, oy)),
            oz,
        ],
        d: [sub(mul(c, dx), mul(s, dy)), add(mul(s, dx), mul(c, dy)), dz],
        d_xy: load(&p.d_xy),
        inv_dz: load(&p.inv_dz),
    };
    let zero = splat(0.0);
    let sky = and(ge(dz, zero), gt(oz, splat(sectors.top_mm)));
    if _mm256_movemask_ps(sky) == 0xff {
        let truth = (splat(f32::INFINITY), splat_u(CODE_SKY));
        return (splat_u(sectors.sky), with_truth.then_some(truth));
    }
    let floor_t = load(&p.floor_t);
    let floor = gt(floor_t, zero);
    let mut near = Nearest {
        t_max: select(floor, floor_t, splat(f32::INFINITY)),
        rank: splat_u(0),
        colour: splat_u(0),
        hit: mask(false),
    };
    if let Some(b) = frame.body.filter(|_| p.may_meet_body) {
        let rank = sectors.rank(Prim::Cylinder(b as u32));
        let limit = near.limits(rank);
        let (found, t, colour) = hit_cylinder(frame, b, &r, limit);
        near.keep(rank, found, t, colour);
    }
    let sector = _mm256_srli_epi32::<{ SECTOR_SHIFT as i32 }>(_mm256_add_epi32(
        load_u(&p.azimuth),
        splat_u(frame.heading),
    ));
    let sector_of = lanes_u(sector);
    let mut left = not(sky);
    while any(left) {
        let first = _mm256_movemask_ps(left).trailing_zeros() as usize;
        let k = sector_of[first];
        let lanes = and(
            left,
            _mm256_castsi256_ps(_mm256_cmpeq_epi32(sector, splat_u(k))),
        );
        left = _mm256_andnot_ps(lanes, left);
        trace_sector(frame, k as usize, lanes, sky, &r, &mut near);
    }
    // The floor's colour where nothing hides it.
    let bare = _mm256_andnot_ps(or(sky, near.hit), floor);
    let (floor_colour, paint) = if any(bare) {
        let paint = floor_paint(frame.scene, &r, near.t_max);
        let colours = palette_colours(&sectors.palette, sectors.palette_lanes.as_ref(), paint);
        (colours, paint)
    } else {
        (splat_u(0), splat_u(0))
    };
    let nothing = or(sky, not(or(near.hit, floor)));
    let seen = select_u(near.hit, near.colour, floor_colour);
    let colour = select_u(nothing, splat_u(sectors.sky), seen);
    (colour, with_truth.then(|| truth(&near, nothing, paint)))
}

/// Each lane's distance to what it meets and what that is ([`crate::render::trace::Code`]):
/// the primitive hit, else the floor's paint, else (`nothing`) the sky.
#[inline]
#[target_feature(enable = "avx2")]
fn truth(near: &Nearest, nothing: V, paint: I) -> (V, I) {
    let floor = _mm256_or_si256(splat_u(CODE_FLOOR), paint);
    let met = select_u(near.hit, near.rank, floor);
    (
        select(nothing, splat(f32::INFINITY), near.t_max),
        select_u(nothing, splat_u(CODE_SKY), met),
    )
}

/// The palette's colours at `paint`: permuted within a register where the palette fits one
/// (eight paints: up to five floor rectangles), else looked up lane by lane (a gather is slower
/// than either on some processors).
#[inline]
#[target_feature(enable = "avx2")]
fn palette_colours(palette: &[u32], lanes: Option<&U>, paint: I) -> I {
    if let Some(table) = lanes {
        return _mm256_permutevar8x32_epi32(load_u(table), paint);
    }
    let colours = lanes_u(paint).map(|k| palette.get(k as usize).copied().unwrap_or(0));
    load_u(&colours)
}

#[inline]
#[target_feature(enable = "avx2")]
fn trace_sector(frame: &FrameRays, sector: usize, lanes: V, sky: V, r: &Rays, near: &mut Nearest) {
    let sectors = frame.sectors;
    let range = sectors.offsets[sector] as usize..sectors.offsets[sector + 1] as usize;
    let lanes = _mm256_andnot_ps(sky, lanes);
    for item in &sectors.items[range] {
        let (open, needed) = lanes_open(item, lanes, r, near, frame.rho);
        if !any(open) {
            break;
        }
        if !any(needed) {
            continue;
        }
        let rank = sectors.rank(item.prim);
        let limit = near.limits(rank);
        let (found, t, colour) = match item.prim {
            Prim::Box(i) => hit_box(frame, i as usize, r, limit),
            Prim::Quad(i) => hit_quad(frame, i as usize, r, limit),
            Prim::Cylinder(i) => hit_cylinder(frame, i as usize, r, limit),
            Prim::Sphere(i) => hit_sphere(frame, i as usize, r, limit),
        };
        near.keep(rank, found, t, colour);
    }
}

#[inline]
#[target_feature(enable = "avx2")]
fn lanes_open(item: &Item, lanes: V, r: &Rays, near: &Nearest, rho: f32) -> (V, V) {
    let reach = add(add(mul(near.t_max, r.d_xy), splat(rho)), splat(1.0));
    let open = _mm256_andnot_ps(ge(splat(item.d_min), reach), lanes);
    // `Item::passes_over`, lane by lane.
    let (oz, dz) = (r.o[2], r.d[2]);
    let above = sub(oz, splat(item.top));
    let steep = gt(mul(above, r.d_xy), mul(splat(item.reach), neg(dz)));
    let over = and(gt(above, splat(0.0)), or(ge(dz, splat(0.0)), steep));
    (open, _mm256_andnot_ps(over, open))
}

/// `trace::slab` lane by lane: whether the ray can be in `[lo, hi]`, and its interval there.
#[inline]
#[target_feature(enable = "avx2")]
fn slab(o: V, d: V, lo: f32, hi: f32) -> (V, V, V) {
    slab_inv(o, d, div(splat(1.0), d), lo, hi)
}

/// [`slab`] with `1 / d` known.
#[inline]
#[target_feature(enable = "avx2")]
fn slab_inv(o: V, d: V, inv: V, lo: f32, hi: f32) -> (V, V, V) {
    let parallel = lt(abs(d), splat(1e-12));
    let ta = mul(sub(splat(lo), o), inv);
    let tb = mul(sub(splat(hi), o), inv);
    let outside = or(lt(o, splat(lo)), gt(o, splat(hi)));
    let ok = or(not(parallel), not(outside));
    let t0 = select(parallel, splat(f32::NEG_INFINITY), _mm256_min_ps(ta, tb));
    let t1 = select(parallel, splat(f32::INFINITY), _mm256_max_ps(ta, tb));
    (ok, t0, t1)
}

/// Whether an entry at `tn` before an exit at `tf` is a hit before `limit`.
#[inline]
#[target_feature(enable = "avx2")]
fn entered(tn: V, tf: V, limit: V) -> V {
    not(or(or(gt(tn, tf), le(tn, splat(T_EPS))), ge(tn, limit)))
}

/// `!v.is_sign_negative()` as 0 or 1.
#[inline]
#[target_feature(enable = "avx2")]
fn along(v: V) -> I {
    _mm256_xor_si256(_mm256_srli_epi32::<31>(_mm256_castps_si256(v)), splat_u(1))
}

/// The colours of a face table ([`crate::render::cpu::FaceColours`]) at each lane's face.
#[inline]
#[target_feature(enable = "avx2")]
fn face_colours(faces: &U, face: I) -> I {
    _mm256_permutevar8x32_epi32(load_u(faces), face)
}

#[inline]
#[target_feature(enable = "avx2")]
fn hit_box(frame: &FrameRays, k: usize, r: &Rays, limit: V) -> (V, V, I) {
    let b = &frame.scene.boxes[k];
    let [cx, cy, hx, hy] = b.geom;
    let [c, sn, base, top] = b.frame;
    let (cv, snv, nsv) = (splat(c), splat(sn), splat(-sn));
    let rx = sub(r.o[0], splat(cx));
    let ry = sub(r.o[1], splat(cy));
    let lox = add(mul(cv, rx), mul(snv, ry));
    let loy = add(mul(nsv, rx), mul(cv, ry));
    let ldx = add(mul(cv, r.d[0]), mul(snv, r.d[1]));
    let ldy = add(mul(nsv, r.d[0]), mul(cv, r.d[1]));
    let (okx, x0, x1) = slab(lox, ldx, -hx, hx);
    let (oky, y0, y1) = slab(loy, ldy, -hy, hy);
    let (okz, z0, z1) = slab_inv(r.o[2], r.d[2], r.inv_dz, base, top);
    let tn = _mm256_max_ps(_mm256_max_ps(x0, y0), z0);
    let tf = _mm256_min_ps(_mm256_min_ps(x1, y1), z1);
    let found = and(and(okx, oky), and(okz, entered(tn, tf, limit)));
    let face = select_u(
        eq(tn, x0),
        along(ldx),
        select_u(
            eq(tn, y0),
            _mm256_add_epi32(splat_u(2), along(ldy)),
            _mm256_add_epi32(splat_u(4), along(r.d[2])),
        ),
    );
    if b.color[3] < 0.0 {
        return (found, tn, face_colours(&frame.sectors.box_faces[k], face));
    }
    // A striped board: the stripe looked up lane by lane where it is hit.
    let f = lanes_f(div(add(add(lox, mul(tn, ldx)), splat(hx)), splat(2.0 * hx)));
    let (hits, faces) = (_mm256_movemask_ps(found), lanes_u(face));
    let mut colour = [0; LANES];
    for i in (0..LANES).filter(|&i| hits & (1 << i) != 0) {
        colour[i] = super::board_colour(frame.scene, b, faces[i] as usize, f[i]);
    }
    (found, tn, load_u(&colour))
}

#[inline]
#[target_feature(enable = "avx2")]
fn hit_quad(frame: &FrameRays, k: usize, r: &Rays, limit: V) -> (V, V, I) {
    let q = &frame.scene.quads[k];
    let sides = &frame.sectors.quad_sides[k];
    let zero = splat(0.0);
    let mut ok = mask(true);
    let (mut tn, mut tf) = (splat(f32::NEG_INFINITY), splat(f32::INFINITY));
    let mut face = splat_u(4);
    for side in 0..4 {
        let (nx, ny) = (splat(sides.nx[side]), splat(sides.ny[side]));
        let (ax, ay) = (splat(sides.ax[side]), splat(sides.ay[side]));
        let num = add(mul(nx, sub(r.o[0], ax)), mul(ny, sub(r.o[1], ay)));
        let den = add(mul(nx, r.d[0]), mul(ny, r.d[1]));
        let t = div(neg(num), den);
        let bounds = ge(abs(den), splat(1e-12));
        ok = and(ok, or(bounds, not(gt(num, zero))));
        let enters = and(and(bounds, lt(den, zero)), gt(t, tn));
        let leaves = and(and(bounds, ge(den, zero)), lt(t, tf));
        tn = select(enters, t, tn);
        face = select_u(enters, splat_u(side as u32), face);
        tf = select(leaves, t, tf);
    }
    let (okz, z0, z1) = slab_inv(r.o[2], r.d[2], r.inv_dz, 0.0, q.z[0]);
    let cap = select_u(sign_negative(r.d[2]), splat_u(4), splat_u(5));
    let capped = gt(z0, tn);
    face = select_u(capped, cap, face);
    tn = select(capped, z0, tn);
    let far = _mm256_min_ps(tf, z1);
    let found = and(and(ok, okz), entered(tn, far, limit));
    (found, tn, face_colours(&frame.sectors.quad_faces[k], face))
}

#[inline]
#[target_feature(enable = "avx2")]
fn hit_cylinder(frame: &FrameRays, k: usize, r: &Rays, limit: V) -> (V, V, I) {
    let cyl = &frame.scene.cylinders[k];
    let [cx, cy, radius, top] = cyl.geom;
    let ([dx, dy, dz], oz) = (r.d, r.o[2]);
    let zero = splat(0.0);
    let mx = sub(r.o[0], splat(cx));
    let my = sub(r.o[1], splat(cy));
    let a = add(mul(dx, dx), mul(dy, dy));
    let b = add(mul(mx, dx), mul(my, dy));
    let c = sub(add(mul(mx, mx), mul(my, my)), splat(radius * radius));
    let disc = sub(mul(b, b), mul(a, c));
    let t = div(sub(neg(b), _mm256_sqrt_ps(disc)), a);
    let z = add(oz, mul(t, dz));
    let side = and(
        and(gt(a, splat(1e-12)), ge(disc, zero)),
        and(
            and(gt(t, splat(T_EPS)), lt(t, limit)),
            and(ge(z, zero), le(z, splat(top))),
        ),
    );
    let t_lim = select(side, t, limit);
    let tt = div(sub(splat(top), oz), dz);
    let (px, py) = (add(mx, mul(tt, dx)), add(my, mul(tt, dy)));
    let on_top = le(add(mul(px, px), mul(py, py)), splat(radius * radius));
    let cap = and(
        and(lt(dz, zero), gt(oz, splat(top))),
        and(and(gt(tt, splat(T_EPS)), lt(tt, t_lim)), on_top),
    );
    let found = or(side, cap);
    let rv = splat(radius);
    let n = [div(add(mx, mul(t, dx)), rv), div(add(my, mul(t, dy)), rv)];
    let side_colour = shade(
        frame.scene,
        [n[0], n[1], zero],
        [cyl.color[0], cyl.color[1], cyl.color[2]],
    );
    let top_colour = splat_u(frame.sectors.cylinder_tops[k]);
    (
        found,
        select(cap, tt, t),
        select_u(cap, top_colour, side_colour),
    )
}

/// The first crossing of sphere `k` beyond `T_EPS`, as `trace::hit_sphere` finds it (with
/// `trace::sphere_crossing`'s steps), and its shaded colour.
#[inline]
#[target_feature(enable = "avx2")]
fn hit_sphere(frame: &FrameRays, k: usize, r: &Rays, limit: V) -> (V, V, I) {
    let sp = &frame.scene.spheres[k];
    let [cx, cy, cz, radius] = sp.geom;
    let [dx, dy, dz] = r.d;
    let mx = sub(r.o[0], splat(cx));
    let my = sub(r.o[1], splat(cy));
    let mz = sub(r.o[2], splat(cz));
    let b = add(add(mul(mx, dx), mul(my, dy)), mul(mz, dz));
    let fx = sub(mx, mul(b, dx));
    let fy = sub(my, mul(b, dy));
    let fz = sub(mz, mul(b, dz));
    let f2 = add(add(mul(fx, fx), mul(fy, fy)), mul(fz, fz));
    let disc = sub(splat(radius * radius), f2);
    let sq = _mm256_sqrt_ps(disc);
    let t0 = sub(neg(b), sq);
    let t1 = add(neg(b), sq);
    let eps = splat(T_EPS);
    let t = select(gt(t0, eps), t0, t1);
    let found = and(ge(disc, splat(0.0)), and(gt(t, eps), lt(t, limit)));
    if !any(found) {
        return (found, t, splat_u(0));
    }
    let rv = splat(radius);
    let n = [
        div(add(mx, mul(t, dx)), rv),
        div(add(my, mul(t, dy)), rv),
        div(add(mz, mul(t, dz)), rv),
    ];
    (
        found,
        t,
        shade(frame.scene, n, [sp.color[0], sp.color[1], sp.color[2]]),
    )
}

/// [`trace::pack`] of [`trace::shade`] for the normal `n` and colour `rgb`, lane by lane:
/// `(light + diffuse max(n . l, 0)) scale`, each channel clamped to 0..1 and rounded to the
/// nearest of 255 levels (a lane whose colour is kept is not NaN: clamping by `min`/`max` is
/// `f32::clamp` there).
#[inline]
#[target_feature(enable = "avx2")]
fn shade(scene: &Scene, n: [V; 3], rgb: [f32; 3]) -> I {
    let g = &scene.globals;
    let dot = add(
        add(mul(n[0], splat(g.light[0])), mul(n[1], splat(g.light[1]))),
        mul(n[2], splat(g.light[2])),
    );
    let lambert = _mm256_max_ps(dot, splat(0.0));
    let k = mul(
        add(splat(g.light[3]), mul(splat(g.light2[0]), lambert)),
        splat(g.light2[1]),
    );
    let level = |c: f32| {
        let x = _mm256_max_ps(_mm256_min_ps(mul(splat(c), k), splat(1.0)), splat(0.0));
        _mm256_cvttps_epi32(add(mul(x, splat(255.0)), splat(0.5)))
    };
    let (r, g, b) = (level(rgb[0]), level(rgb[1]), level(rgb[2]));
    let rg = _mm256_or_si256(r, _mm256_slli_epi32::<8>(g));
    let rgb = _mm256_or_si256(rg, _mm256_slli_epi32::<16>(b));
    _mm256_or_si256(rgb, splat_u(255 << 24))
}

/// [`trace::floor_paint`] lane by lane at each ray's floor point (`t` along it): the index of
/// its shaded colour in the palette.
#[inline]
#[target_feature(enable = "avx2")]
fn floor_paint(scene: &Scene, r: &Rays, t: V) -> I {
    let g = &scene.globals;
    let x = add(r.o[0], mul(t, r.d[0]));
    let y = add(r.o[1], mul(t, r.d[1]));
    let mut inside = mask(g.flags[1] == 0);
    let mut mark = splat_u(u32::MAX);
    for (k, rect) in scene.floor_rects.iter().enumerate() {
        let dx = sub(x, splat(rect.geom[0]));
        let dy = sub(y, splat(rect.geom[1]));
        let (f0, f1) = (splat(rect.frame[0]), splat(rect.frame[1]));
        let lx = add(mul(f0, dx), mul(f1, dy));
        let ly = add(mul(splat(-rect.frame[1]), dx), mul(f0, dy));
        let in_rect = and(
            le(abs(lx), splat(rect.geom[2])),
            le(abs(ly), splat(rect.geom[3])),
        );
        if rect.frame[2] == FLOOR_REGION {
            inside = or(inside, in_rect);
            continue;
        }
        let covered = if rect.frame[2] == SQUARE_MARK {
            in_rect
        } else {
            let radius2 = splat(rect.geom[2] * rect.geom[2]);
            le(add(mul(lx, lx), mul(ly, ly)), radius2)
        };
        mark = select_u(covered, splat_u(k as u32), mark);
    }
    let n = scene.floor_rects.len() as u32;
    let mut paint = select_u(inside, splat_u(n + 2), splat_u(n));
    if g.flags[0] != 0 {
        let [a1, b, w, cr] = g.field;
        let (ax, ay) = (abs(x), abs(y));
        let boundary = or(ge(ax, splat(a1 - w)), ge(ay, splat(b - w)));
        let centre = le(ax, splat(0.5 * w));
        let rho = _mm256_sqrt_ps(add(mul(x, x), mul(y, y)));
        let circle = le(abs(sub(rho, splat(cr))), splat(0.5 * w));
        let [front, front_in, side, side_in] = g.field2;
        let defense = and(
            and(ge(ax, splat(front)), le(ay, splat(side))),
            or(le(ax, splat(front_in)), ge(ay, splat(side_in))),
        );
        let on_field = and(le(ax, splat(a1)), le(ay, splat(b)));
        let marks = or(or(boundary, centre), or(circle, defense));
        let line = and(and(inside, on_field), marks);
        paint = select_u(line, splat_u(n + 1), paint);
    }
    let marked = not(_mm256_castsi256_ps(_mm256_cmpeq_epi32(
        mark,
        splat_u(u32::MAX),
    )));
    select_u(marked, mark, paint)
}
