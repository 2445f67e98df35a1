// omniloop catadioptric tracer: one invocation per pixel of each frame of a batch (z: frame).
// camera ray -> mirror (hyperbolic, conical, spherical) or pinhole -> scene (floor, boxes,
// quadrilateral prisms, cylinders, spheres, striped boards) -> Lambert shading -> packed RGBA8;
// a frame that asks for its truth also gets, per pixel, the distance along the scene ray to what
// it meets and what that is (trace.rs: Code).
// The scene half matches sim/src/render/trace.rs operation for operation.

struct Globals {
    field: vec4<f32>,       // A1, B, line width, centre circle radius
    flags: vec4<u32>,       // field present, any floor region, box count, cylinder count
    counts: vec4<u32>,      // floor rect count, board count, quad count, sphere count
    floor_rgb: vec4<f32>,
    outside_rgb: vec4<f32>,
    line_rgb: vec4<f32>,
    sky_rgb: vec4<f32>,
    light: vec4<f32>,       // direction xyz, ambient
    light2: vec4<f32>,      // diffuse, normalisation
    field2: vec4<f32>,      // defense lines: |x| of the front's edges, |y| of the sides' (< 0: none)
};

struct SensorParams {
    size: vec4<u32>,        // width, height, kind, truth (0: none, else 1 + its first pixel)
    intr: vec4<f32>,        // cx, cy, focal, noise sigma (0: none)
    p0: vec4<f32>,
    p1: vec4<f32>,
    p2: vec4<f32>,
    p3: vec4<f32>,          // calibrated: image circle (< 0: none), principal u, v, coefficients
    p4: vec4<f32>,          // calibrated: the model's intrinsics (gpu.rs: SensorParams::new)
    p5: vec4<f32>,
    p6: vec4<f32>,
    mount: vec4<f32>,       // axis offset on the robot x, y
    pose: vec4<f32>,        // robot x, y, cos(theta), sin(theta)
};

struct BoxPrim { geom: vec4<f32>, frame: vec4<f32>, color: vec4<f32> };
struct CylinderPrim { geom: vec4<f32>, color: vec4<f32>, top: vec4<f32> };
struct BoardPrim { range: vec4<u32>, color_a: vec4<f32>, color_b: vec4<f32> };
struct FloorRectPrim { geom: vec4<f32>, frame: vec4<f32>, color: vec4<f32> };
struct QuadPrim { c01: vec4<f32>, c23: vec4<f32>, z: vec4<f32>, color: vec4<f32> };
struct SpherePrim { geom: vec4<f32>, color: vec4<f32> };

// One frame of a batch: its scene's scalars, its sensor and pose, and where its primitives and
// pixels start in the shared arrays.
struct Frame {
    g: Globals,
    sensor: SensorParams,
    // Where the frame's first element of each scene list is, at that list's word (FIRST_BOXES,
    // ...: gpu.rs lays them out from SCENE_LISTS); its first pixel, its noise key.
    offsets: array<vec4<u32>, 3>,
};

// The scene lists (boxes, cylinders, boards, stripe_edges, floor_rects, quads, spheres) are
// bound by the declarations gpu.rs puts before this file, from SCENE_LISTS.
@group(0) @binding(0) var<storage, read> frames: array<Frame>;
@group(0) @binding(7) var<storage, read_write> pixels: array<u32>;
// Standard normal quantiles (sim/src/render/noise.rs: gauss_table).
@group(0) @binding(9) var<storage, read> gauss: array<f32>;
// Per pixel of the frames that ask for their truth: the distance t along the scene ray (f32
// bits) and what the ray meets (a code, as trace.rs's Code), the frames one after the other.
@group(0) @binding(10) var<storage, read_write> truth: array<vec2<u32>>;

// The invocation's frame (global_invocation_id.z), read once in main.
var<private> g: Globals;
var<private> sensor: SensorParams;
var<private> offsets: array<vec4<u32>, 3>;

// The frame's offset word `word`: the first element of a list, its first pixel, its noise key.
fn first(word: u32) -> u32 {
    return offsets[word / 4u][word % 4u];
}

const T_EPS: f32 = 1e-3;
const BIG: f32 = 3.0e38;
const BLACK: u32 = 0xff000000u;
// The codes of what a pixel shows (trace.rs: Code): a primitive's rank from 1 (boxes, quads,
// cylinders, spheres), the floor bit with the paint's index, the sky, or no mirror at all.
const CODE_FLOOR: u32 = 0x80000000u;
const CODE_SKY: u32 = 0xffffffffu;
const CODE_NOTHING: u32 = 0xfffffffeu;
// The bits of t for the sky (+infinity) and for a pixel that sees no mirror (NaN, Rust's
// f32::NAN).
const T_SKY: u32 = 0x7f800000u;
const T_NOTHING: u32 = 0x7fc00000u;

struct Ray { o: vec3<f32>, d: vec3<f32>, ok: bool };
struct Hit { t: f32, n: vec3<f32>, rgb: vec3<f32>, ok: bool };

fn no_hit() -> Hit { return Hit(BIG, vec3<f32>(0.0), vec3<f32>(0.0), false); }

fn reflect_n(d: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return d - n * (2.0 * dot(d, n));
}

// Roots of a t^2 + b t + c = 0 in increasing order (x, y); z > 0 when real.
fn quadratic(a: f32, b: f32, c: f32) -> vec3<f32> {
    if (abs(a) < 1e-30) {
        if (abs(b) < 1e-30) { return vec3<f32>(0.0, 0.0, -1.0); }
        let t = -c / b;
        return vec3<f32>(t, t, 1.0);
    }
    let disc = b * b - 4.0 * a * c;
    if (disc < 0.0) { return vec3<f32>(0.0, 0.0, -1.0); }
    var sb = 1.0;
    if (b < 0.0) { sb = -1.0; }
    let q = -0.5 * (b + sb * sqrt(disc));
    var t0 = 0.0;
    var t1 = 0.0;
    if (q != 0.0) { t0 = q / a; t1 = c / q; }
    return vec3<f32>(min(t0, t1), max(t0, t1), 1.0);
}

// Mei's unified model's ray of normalised distorted coordinates (xd, yd) in its frame
// (sim/src/optics/calibrated.rs, vision's UnifiedModel::unproject): the radial-tangential
// distortion undone by 20 fixed-point steps, then the lift to the sphere (Mei and Rives eq. (6)).
fn unified_ray(xd: f32, yd: f32) -> vec4<f32> {
    let k1 = sensor.p5.x;
    let k2 = sensor.p5.y;
    let q1 = sensor.p5.z;
    let q2 = sensor.p5.w;
    var x = xd;
    var y = yd;
    for (var i = 0; i < 20; i = i + 1) {
        let r2 = x * x + y * y;
        let radial = 1.0 + k1 * r2 + k2 * r2 * r2;
        if (abs(radial) < 1e-12) { return vec4<f32>(0.0); }
        let tx = 2.0 * q1 * x * y + q2 * (r2 + 2.0 * x * x);
        let ty = q1 * (r2 + 2.0 * y * y) + 2.0 * q2 * x * y;
        x = (xd - tx) / radial;
        y = (yd - ty) / radial;
    }
    let r2 = x * x + y * y;
    let radial = 1.0 + k1 * r2 + k2 * r2 * r2;
    let mx = x * radial + 2.0 * q1 * x * y + q2 * (r2 + 2.0 * x * x) - xd;
    let my = y * radial + q1 * (r2 + 2.0 * y * y) + 2.0 * q2 * x * y - yd;
    if (!(length(vec2<f32>(mx, my)) <= 1e-5 * (1.0 + length(vec2<f32>(xd, yd))))) {
        return vec4<f32>(0.0);
    }
    let xi = sensor.p4.w;
    let disc = 1.0 + (1.0 - xi * xi) * r2;
    if (disc < 0.0) { return vec4<f32>(0.0); }
    let l = (xi + sqrt(disc)) / (1.0 + r2);
    if (l <= 0.0) { return vec4<f32>(0.0); }
    return vec4<f32>(l * x, l * y, l - xi, 1.0);
}

// The double sphere model's ray of pixel (u, v) (Usenko et al. eq. (46)-(51)).
fn double_sphere_ray(u: f32, v: f32) -> vec4<f32> {
    let xi = sensor.p4.z;
    let alpha = sensor.p4.w;
    let mx = (u - sensor.p3.y) / sensor.p4.x;
    let my = (v - sensor.p3.z) / sensor.p4.y;
    let r2 = mx * mx + my * my;
    let inner = 1.0 - (2.0 * alpha - 1.0) * r2;
    if (inner < 0.0) { return vec4<f32>(0.0); }
    let mz = (1.0 - alpha * alpha * r2) / (alpha * sqrt(inner) + 1.0 - alpha);
    let disc = mz * mz + (1.0 - xi * xi) * r2;
    if (disc < 0.0) { return vec4<f32>(0.0); }
    let k = (mz * xi + sqrt(disc)) / (mz * mz + r2);
    return vec4<f32>(k * mx, k * my, k * mz - xi, 1.0);
}

// OCamCalib's cam2world of pixel (u, v): (x', y') = A^-1 (row - x_c, col - y_c), ray
// (x', y', f(rho)) (Scaramuzza et al. eq. (6)).
fn ocam_ray(u: f32, v: f32) -> vec4<f32> {
    let c = sensor.p4.x;
    let dd = sensor.p4.y;
    let e = sensor.p4.z;
    let dr = v - sensor.p3.z;
    let dc = u - sensor.p3.y;
    let inv = 1.0 / (c - dd * e);
    let xp = inv * (dr - dd * dc);
    let yp = inv * (-e * dr + c * dc);
    let rho = sqrt(xp * xp + yp * yp);
    let coef = array<f32, 9>(sensor.p4.w, sensor.p5.x, sensor.p5.y, sensor.p5.z, sensor.p5.w,
        sensor.p6.x, sensor.p6.y, sensor.p6.z, sensor.p6.w);
    var f = 0.0;
    for (var i = i32(sensor.p3.w) - 1; i >= 0; i = i - 1) {
        f = f * rho + coef[i];
    }
    return vec4<f32>(xp, yp, f, 1.0);
}

// A calibrated camera's scene ray (sim/src/optics/calibrated.rs): the model's unprojection,
// turned by the model frame's rotation (rows in p0..p2 xyz), from its viewpoint (their w).
fn calibrated_ray(kind: u32, x: f32, y: f32) -> Ray {
    var fail = Ray(vec3<f32>(0.0), vec3<f32>(0.0), false);
    if (kind > 6u) { return fail; }
    if (sensor.p3.x >= 0.0 && x * x + y * y > sensor.p3.x * sensor.p3.x) { return fail; }
    let u = sensor.p3.y + x;
    let v = sensor.p3.z - y;
    var m = vec4<f32>(0.0);
    if (kind == 4u) {
        let yd = (v - sensor.p3.z) / sensor.p4.y;
        m = unified_ray((u - sensor.p3.y - sensor.p4.z * yd) / sensor.p4.x, yd);
    } else if (kind == 5u) {
        m = double_sphere_ray(u, v);
    } else {
        m = ocam_ray(u, v);
    }
    if (m.w == 0.0) { return fail; }
    let dm = normalize(m.xyz);
    let dir = vec3<f32>(dot(sensor.p0.xyz, dm), dot(sensor.p1.xyz, dm), dot(sensor.p2.xyz, dm));
    return Ray(vec3<f32>(sensor.p0.w, sensor.p1.w, sensor.p2.w), dir, true);
}

// R v and R^T v for the mounting's tilt R, its rows in p4..p6 (xyz).
fn tilt(v: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(sensor.p4.xyz, v), dot(sensor.p5.xyz, v), dot(sensor.p6.xyz, v));
}
fn untilt(v: vec3<f32>) -> vec3<f32> {
    return sensor.p4.xyz * v.x + sensor.p5.xyz * v.y + sensor.p6.xyz * v.z;
}

// A mirror off its place (sim/src/optics/mounting.rs): the camera's ray taken into the nominal
// mirror's frame, met with its surface from that origin, and the reflected ray moved back.
fn mounted_ray(kind: u32, x: f32, y: f32) -> Ray {
    var fail = Ray(vec3<f32>(0.0), vec3<f32>(0.0), false);
    let pivot = vec3<f32>(0.0, 0.0, sensor.p3.x);
    let offset = vec3<f32>(sensor.p4.w, sensor.p5.w, sensor.p6.w);
    let z0 = vec3<f32>(0.0, 0.0, sensor.p3.z);
    let d = untilt(normalize(vec3<f32>(x, y, sensor.intr.z)));
    let o = untilt(vec3<f32>(0.0, 0.0, sensor.p3.y) - pivot - offset) + pivot - z0;
    var t = -1.0;
    var n = vec3<f32>(0.0);
    if (kind == 0u) {
        let a2 = sensor.p0.x * sensor.p0.x;
        let b2 = sensor.p0.y * sensor.p0.y;
        let roots = quadratic(d.z * d.z / b2 - (d.x * d.x + d.y * d.y) / a2,
            2.0 * (o.z * d.z / b2 - (o.x * d.x + o.y * d.y) / a2),
            o.z * o.z / b2 - (o.x * o.x + o.y * o.y) / a2 - 1.0);
        if (roots.z < 0.0) { return fail; }
        if (roots.x > 0.0 && o.z + roots.x * d.z > 0.0) {
            t = roots.x;
        } else if (roots.y > 0.0 && o.z + roots.y * d.z > 0.0) {
            t = roots.y;
        }
        if (t <= 0.0) { return fail; }
        let p = o + d * t;
        if (p.x * p.x + p.y * p.y > sensor.p1.x * sensor.p1.x) { return fail; }
        n = normalize(vec3<f32>(p.x / a2, p.y / a2, -p.z / b2));
    } else if (kind == 1u) {
        let k2 = sensor.p0.x * sensor.p0.x;
        let h = o.z - sensor.p0.y;
        let roots = quadratic(d.x * d.x + d.y * d.y - k2 * d.z * d.z,
            2.0 * (o.x * d.x + o.y * d.y) - 2.0 * k2 * h * d.z,
            o.x * o.x + o.y * o.y - k2 * h * h);
        if (roots.z < 0.0) { return fail; }
        if (roots.x > 0.0 && h + roots.x * d.z >= 0.0) {
            t = roots.x;
        } else if (roots.y > 0.0 && h + roots.y * d.z >= 0.0) {
            t = roots.y;
        }
        if (t <= 0.0) { return fail; }
        let p = o + d * t;
        let rho = sqrt(p.x * p.x + p.y * p.y);
        if (rho > sensor.p0.z || rho < 1e-12) { return fail; }
        n = normalize(vec3<f32>(p.x / rho, p.y / rho, -sensor.p0.x));
    } else {
        let oc = o - vec3<f32>(0.0, 0.0, sensor.p0.y);
        let r = sensor.p0.x;
        let roots = quadratic(1.0, 2.0 * dot(d, oc), dot(oc, oc) - r * r);
        if (roots.z < 0.0 || roots.x <= 0.0) { return fail; }
        t = roots.x;
        n = (oc + d * t) / r;
    }
    let s = o + d * t + z0;
    return Ray(tilt(s - pivot) + pivot + offset, tilt(reflect_n(d, n)), true);
}

// The scene ray of image coordinates (x, y) in the robot frame (see sim/src/optics).
fn scene_ray(x: f32, y: f32) -> Ray {
    let kind = sensor.size.z;
    if (kind >= 4u) { return calibrated_ray(kind, x, y); }
    if (kind <= 2u && sensor.p3.w > 0.5) { return mounted_ray(kind, x, y); }
    let f = sensor.intr.z;
    var fail = Ray(vec3<f32>(0.0), vec3<f32>(0.0), false);
    if (kind == 3u) {
        let dir = normalize(sensor.p0.xyz * f + sensor.p1.xyz * x + sensor.p2.xyz * y);
        return Ray(vec3<f32>(0.0, 0.0, sensor.p0.w), dir, true);
    }
    let d = normalize(vec3<f32>(x, y, f));
    if (kind == 0u) {
        // Hyperboloid Z^2/b^2 - rho^2/a^2 = 1, camera at (0, 0, -c).
        let a = sensor.p0.x;
        let b = sensor.p0.y;
        let c = sensor.p0.z;
        let rho2 = d.x * d.x + d.y * d.y;
        let roots = quadratic(d.z * d.z - rho2 * b * b / (a * a), -2.0 * c * d.z, c * c - b * b);
        if (roots.z < 0.0) { return fail; }
        var t = -1.0;
        if (roots.x > 0.0 && -c + roots.x * d.z > 0.0) {
            t = roots.x;
        } else if (roots.y > 0.0 && -c + roots.y * d.z > 0.0) {
            t = roots.y;
        }
        if (t <= 0.0) { return fail; }
        let p = vec3<f32>(t * d.x, t * d.y, -c + t * d.z);
        let rim = sensor.p1.x;
        if (p.x * p.x + p.y * p.y > rim * rim) { return fail; }
        let n = normalize(vec3<f32>(p.x / (a * a), p.y / (a * a), -p.z / (b * b)));
        return Ray(vec3<f32>(p.x, p.y, p.z + sensor.p0.w), reflect_n(d, n), true);
    }
    if (kind == 1u) {
        // Cone rho = (z - tip) k, tip above the pinhole.
        let k = sensor.p0.x;
        let tip = sensor.p0.y;
        let rho_d = sqrt(d.x * d.x + d.y * d.y);
        let den = k * d.z - rho_d;
        if (den <= 0.0) { return fail; }
        let t = k * tip / den;
        let p = d * t;
        let rho = rho_d * t;
        if (rho > sensor.p0.z || rho < 1e-12) { return fail; }
        let n = normalize(vec3<f32>(p.x / rho, p.y / rho, -k));
        return Ray(vec3<f32>(p.x, p.y, p.z + sensor.p0.w), reflect_n(d, n), true);
    }
    // Sphere of radius p0.x centred p0.y above the pinhole.
    let r = sensor.p0.x;
    let centre = vec3<f32>(0.0, 0.0, sensor.p0.y);
    let roots = quadratic(1.0, -2.0 * dot(d, centre), dot(centre, centre) - r * r);
    if (roots.z < 0.0 || roots.x <= 0.0) { return fail; }
    let p = d * roots.x;
    let n = (p - centre) / r;
    return Ray(vec3<f32>(p.x, p.y, p.z + sensor.p0.z), reflect_n(d, n), true);
}

// What covers the floor at (x, y), as trace.rs's paint_index: mark i (the last that covers the
// point) is i, then outside every region n, a line n + 1 and the bare floor n + 2, with n the
// floor rects' count.
fn floor_paint(x: f32, y: f32) -> u32 {
    let n = g.counts.x;
    var inside = g.flags.y == 0u;
    var mark = -1;
    for (var i = 0u; i < n; i = i + 1u) {
        let r = floor_rects[first(FIRST_FLOOR_RECTS) + i];
        let dx = x - r.geom.x;
        let dy = y - r.geom.y;
        let lx = r.frame.x * dx + r.frame.y * dy;
        let ly = -r.frame.y * dx + r.frame.x * dy;
        let in_rect = abs(lx) <= r.geom.z && abs(ly) <= r.geom.w;
        if (r.frame.z == 0.0) {
            if (in_rect) { inside = true; }
        } else if (r.frame.z == 1.0) {
            if (in_rect) { mark = i32(i); }
        } else if (lx * lx + ly * ly <= r.geom.z * r.geom.z) {
            mark = i32(i);
        }
    }
    if (mark >= 0) { return u32(mark); }
    if (!inside) { return n; }
    if (g.flags.x != 0u) {
        let ax = abs(x);
        let ay = abs(y);
        let a1 = g.field.x;
        let b = g.field.y;
        let w = g.field.z;
        if (ax <= a1 && ay <= b) {
            let boundary = ax >= a1 - w || ay >= b - w;
            let centre = ax <= 0.5 * w;
            let circle = abs(sqrt(x * x + y * y) - g.field.w) <= 0.5 * w;
            let d = g.field2;
            let defense = ax >= d.x && ay <= d.z && (ax <= d.y || ay >= d.w);
            if (boundary || centre || circle || defense) { return n + 1u; }
        }
    }
    return n + 2u;
}

// The colour of floor paint `k` (floor_paint's index).
fn paint_color(k: u32) -> vec3<f32> {
    let n = g.counts.x;
    if (k < n) { return floor_rects[first(FIRST_FLOOR_RECTS) + k].color.xyz; }
    if (k == n) { return g.outside_rgb.xyz; }
    if (k == n + 1u) { return g.line_rgb.xyz; }
    return g.floor_rgb.xyz;
}

// Slab interval (x, y); z < 0 when parallel and outside.
fn slab(o: f32, d: f32, lo: f32, hi: f32) -> vec3<f32> {
    if (abs(d) < 1e-12) {
        if (o < lo || o > hi) { return vec3<f32>(0.0, 0.0, -1.0); }
        return vec3<f32>(-BIG, BIG, 1.0);
    }
    let inv = 1.0 / d;
    let ta = (lo - o) * inv;
    let tb = (hi - o) * inv;
    return vec3<f32>(min(ta, tb), max(ta, tb), 1.0);
}

fn sgn(x: f32) -> f32 {
    if (x > 0.0) { return 1.0; }
    if (x < 0.0) { return -1.0; }
    return 0.0;
}

fn hit_box(b: BoxPrim, o: vec3<f32>, d: vec3<f32>, t_max: f32) -> Hit {
    let c = b.frame.x;
    let s = b.frame.y;
    let hx = b.geom.z;
    let hy = b.geom.w;
    let rx = o.x - b.geom.x;
    let ry = o.y - b.geom.y;
    let lox = c * rx + s * ry;
    let loy = -s * rx + c * ry;
    let ldx = c * d.x + s * d.y;
    let ldy = -s * d.x + c * d.y;
    let sx = slab(lox, ldx, -hx, hx);
    let sy = slab(loy, ldy, -hy, hy);
    let sz = slab(o.z, d.z, b.frame.z, b.frame.w);
    if (sx.z < 0.0 || sy.z < 0.0 || sz.z < 0.0) { return no_hit(); }
    let tn = max(max(sx.x, sy.x), sz.x);
    let tf = min(min(sx.y, sy.y), sz.y);
    if (tn > tf || tn <= T_EPS || tn >= t_max) { return no_hit(); }
    var n = vec3<f32>(0.0, 0.0, -sgn(d.z));
    if (tn == sx.x) {
        let nx = -sgn(ldx);
        n = vec3<f32>(c * nx, s * nx, 0.0);
    } else if (tn == sy.x) {
        let ny = -sgn(ldy);
        n = vec3<f32>(-s * ny, c * ny, 0.0);
    }
    var rgb = b.color.xyz;
    if (b.color.w >= 0.0 && tn != sx.x) {
        let board = boards[first(FIRST_BOARDS) + u32(b.color.w)];
        let f = (lox + tn * ldx + hx) / (2.0 * hx);
        let first_edge = board.range.x;
        let count = board.range.y;
        var k = 0u;
        if (count > 0u) { k = count - 1u; }
        for (var i = 0u; i < count; i = i + 1u) {
            if (f <= stripe_edges[first(FIRST_STRIPE_EDGES) + first_edge + i]) { k = i; break; }
        }
        if (k % 2u == 0u) { rgb = board.color_a.xyz; } else { rgb = board.color_b.xyz; }
    }
    return Hit(tn, n, rgb, true);
}

fn quad_corner(q: QuadPrim, i: u32) -> vec2<f32> {
    if (i == 0u) { return q.c01.xy; }
    if (i == 1u) { return q.c01.zw; }
    if (i == 2u) { return q.c23.xy; }
    return q.c23.zw;
}

fn hit_quad(q: QuadPrim, o: vec3<f32>, d: vec3<f32>, t_max: f32) -> Hit {
    var tn = -BIG;
    var tf = BIG;
    var n = vec3<f32>(0.0);
    for (var i = 0u; i < 4u; i = i + 1u) {
        let a = quad_corner(q, i);
        let b = quad_corner(q, (i + 1u) % 4u);
        let ex = b.x - a.x;
        let ey = b.y - a.y;
        let len = sqrt(ex * ex + ey * ey);
        if (len < 1e-6) { continue; }
        // Outward normal of a counter-clockwise side.
        let nx = ey / len;
        let ny = -ex / len;
        let num = nx * (o.x - a.x) + ny * (o.y - a.y);
        let den = nx * d.x + ny * d.y;
        if (abs(den) < 1e-12) {
            if (num > 0.0) { return no_hit(); }
            continue;
        }
        let t = -num / den;
        if (den < 0.0) {
            if (t > tn) { tn = t; n = vec3<f32>(nx, ny, 0.0); }
        } else if (t < tf) {
            tf = t;
        }
    }
    let sz = slab(o.z, d.z, 0.0, q.z.x);
    if (sz.z < 0.0) { return no_hit(); }
    if (sz.x > tn) { tn = sz.x; n = vec3<f32>(0.0, 0.0, -sgn(d.z)); }
    tf = min(tf, sz.y);
    if (tn > tf || tn <= T_EPS || tn >= t_max) { return no_hit(); }
    return Hit(tn, n, q.color.xyz, true);
}

fn hit_cylinder(cy: CylinderPrim, o: vec3<f32>, d: vec3<f32>, t_max: f32) -> Hit {
    let r = cy.geom.z;
    let top = cy.geom.w;
    let mx = o.x - cy.geom.x;
    let my = o.y - cy.geom.y;
    var best = no_hit();
    var t_lim = t_max;
    let a = d.x * d.x + d.y * d.y;
    if (a > 1e-12) {
        let b = mx * d.x + my * d.y;
        let c = mx * mx + my * my - r * r;
        let disc = b * b - a * c;
        if (disc >= 0.0) {
            let t = (-b - sqrt(disc)) / a;
            let z = o.z + t * d.z;
            if (t > T_EPS && t < t_lim && z >= 0.0 && z <= top) {
                t_lim = t;
                best = Hit(t, vec3<f32>((mx + t * d.x) / r, (my + t * d.y) / r, 0.0), cy.color.xyz, true);
            }
        }
    }
    if (d.z < 0.0 && o.z > top) {
        let t = (top - o.z) / d.z;
        let px = mx + t * d.x;
        let py = my + t * d.y;
        if (t > T_EPS && t < t_lim && px * px + py * py <= r * r) {
            best = Hit(t, vec3<f32>(0.0, 0.0, 1.0), cy.top.xyz, true);
        }
    }
    return best;
}

// The first crossing of a sphere beyond T_EPS (trace.rs: sphere_crossing, hit_sphere): the
// discriminant as r^2 less the squared distance of the line from the centre.
fn hit_sphere(sp: SpherePrim, o: vec3<f32>, d: vec3<f32>, t_max: f32) -> Hit {
    let r = sp.geom.w;
    let mx = o.x - sp.geom.x;
    let my = o.y - sp.geom.y;
    let mz = o.z - sp.geom.z;
    let b = mx * d.x + my * d.y + mz * d.z;
    let fx = mx - b * d.x;
    let fy = my - b * d.y;
    let fz = mz - b * d.z;
    let disc = r * r - (fx * fx + fy * fy + fz * fz);
    if (disc < 0.0) { return no_hit(); }
    let sq = sqrt(disc);
    let t0 = -b - sq;
    let t1 = -b + sq;
    var t = t1;
    if (t0 > T_EPS) { t = t0; }
    if (!(t > T_EPS && t < t_max)) { return no_hit(); }
    let n = vec3<f32>((mx + t * d.x) / r, (my + t * d.y) / r, (mz + t * d.z) / r);
    return Hit(t, n, sp.color.xyz, true);
}

fn pack(c: vec3<f32>) -> u32 {
    let q = vec3<u32>(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)) * 255.0 + 0.5);
    return q.x | (q.y << 8u) | (q.z << 16u) | (255u << 24u);
}

// Wellons' lowbias32 integer hash (noise.rs: mix32).
fn mix32(x0: u32) -> u32 {
    var x = x0;
    x = x ^ (x >> 16u);
    x = x * 0x7feb352du;
    x = x ^ (x >> 15u);
    x = x * 0x846ca68bu;
    return x ^ (x >> 16u);
}

// clamp(floor(level + sigma z + 0.5), 0, 255) (noise.rs: noisy_level).
fn noisy(level: u32, sigma: f32, z: f32) -> u32 {
    return u32(clamp(f32(level) + sigma * z + 0.5, 0.0, 255.0));
}

// Pixel `i` of the frame with its sensor noise, drawn as noise.rs draws it from the frame's
// key: a pure function of the key, the pixel and the channel.
fn with_noise(p: u32, i: u32) -> u32 {
    let sigma = sensor.intr.w;
    if (sigma <= 0.0) { return p; }
    let m = mix32(i) ^ first(NOISE_KEY);
    let h1 = mix32(m);
    let h2 = mix32(m ^ 0x9e3779b9u);
    let r = noisy(p & 0xffu, sigma, gauss[h1 & 0xffffu]);
    let gr = noisy((p >> 8u) & 0xffu, sigma, gauss[h1 >> 16u]);
    let b = noisy((p >> 16u) & 0xffu, sigma, gauss[h2 & 0xffffu]);
    return r | (gr << 8u) | (b << 16u) | (p & 0xff000000u);
}

// What a world ray meets first: the hit (not ok: the sky) and its code (trace.rs: trace_ray).
struct Seen { hit: Hit, code: u32 };

// The world ray o + t d traced against the floor and every primitive, in trace.rs's order.
fn trace_scene(o: vec3<f32>, d: vec3<f32>) -> Seen {
    var best = no_hit();
    var code = CODE_SKY;
    var t_max = BIG;
    if (d.z < 0.0) {
        let t = -o.z / d.z;
        if (t > T_EPS) {
            let paint = floor_paint(o.x + t * d.x, o.y + t * d.y);
            best = Hit(t, vec3<f32>(0.0, 0.0, 1.0), paint_color(paint), true);
            code = CODE_FLOOR | paint;
            t_max = t;
        }
    }
    // Ranks from 1 in the order of RANKED (scene.rs): boxes, then quads, cylinders, spheres.
    var rank = 1u;
    for (var i = 0u; i < g.flags.z; i = i + 1u) {
        let hb = hit_box(boxes[first(FIRST_BOXES) + i], o, d, t_max);
        if (hb.ok) { best = hb; t_max = hb.t; code = rank + i; }
    }
    rank = rank + g.flags.z;
    for (var i = 0u; i < g.counts.z; i = i + 1u) {
        let hq = hit_quad(quads[first(FIRST_QUADS) + i], o, d, t_max);
        if (hq.ok) { best = hq; t_max = hq.t; code = rank + i; }
    }
    rank = rank + g.counts.z;
    for (var i = 0u; i < g.flags.w; i = i + 1u) {
        let hc = hit_cylinder(cylinders[first(FIRST_CYLINDERS) + i], o, d, t_max);
        if (hc.ok) { best = hc; t_max = hc.t; code = rank + i; }
    }
    rank = rank + g.flags.w;
    for (var i = 0u; i < g.counts.w; i = i + 1u) {
        let hs = hit_sphere(spheres[first(FIRST_SPHERES) + i], o, d, t_max);
        if (hs.ok) { best = hs; t_max = hs.t; code = rank + i; }
    }
    return Seen(best, code);
}

// Pixel `local` of the frame: its colour and, when the frame asks for its truth, its t (bits)
// and code.
fn put(index: u32, local: u32, colour: u32, t_bits: u32, code: u32) {
    pixels[index] = with_noise(colour, local);
    if (sensor.size.w != 0u) {
        truth[sensor.size.w - 1u + local] = vec2<u32>(t_bits, code);
    }
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let fr = frames[id.z];
    g = fr.g;
    sensor = fr.sensor;
    offsets = fr.offsets;
    let w = sensor.size.x;
    let h = sensor.size.y;
    if (id.x >= w || id.y >= h) { return; }
    let local = id.y * w + id.x;
    let index = first(FIRST_PIXEL) + local;
    let x = f32(id.x) + 0.5 - sensor.intr.x;
    let y = sensor.intr.y - (f32(id.y) + 0.5);
    let ray = scene_ray(x, y);
    if (!ray.ok) {
        put(index, local, BLACK, T_NOTHING, CODE_NOTHING);
        return;
    }
    // Robot frame -> world.
    let c = sensor.pose.z;
    let s = sensor.pose.w;
    let ro = vec3<f32>(ray.o.x + sensor.mount.x, ray.o.y + sensor.mount.y, ray.o.z);
    let o = vec3<f32>(sensor.pose.x + c * ro.x - s * ro.y, sensor.pose.y + s * ro.x + c * ro.y, ro.z);
    let d = vec3<f32>(c * ray.d.x - s * ray.d.y, s * ray.d.x + c * ray.d.y, ray.d.z);
    let seen = trace_scene(o, d);
    if (!seen.hit.ok) {
        put(index, local, pack(g.sky_rgb.xyz), T_SKY, CODE_SKY);
        return;
    }
    let k = (g.light.w + g.light2.x * max(dot(seen.hit.n, g.light.xyz), 0.0)) * g.light2.y;
    put(index, local, pack(seen.hit.rgb * k), bitcast<u32>(seen.hit.t), seen.code);
}
