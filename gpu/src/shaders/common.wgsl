// What every trace kernel shares: the parameters, the ray of this invocation (as core's
// geometry::Ray makes it), the slab test of core's geometry::slab and its NaN rule, and the
// barrier that keeps a product from being fused into the sum that reads it.

// core's geometry::slab::SLACK: 2^-16, the relative widening of exits and of the closest hit.
const SLACK: f32 = 1.52587890625e-5;
const MISS: u32 = 0xffffffffu;

struct Params {
    origin: vec4<f32>,
    forward: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    // The tree's bounds (CWBVH: its first box test); root_lo.w = 1 when it holds triangles.
    root_lo: vec4<f32>,
    root_hi: vec4<f32>,
    inv_w: f32,
    inv_h: f32,
    width: u32,
    height: u32,
    // Rays in this dispatch (a list), or rows of the frame (a camera).
    count: u32,
    // First ray (list) or row (camera) of this dispatch: big jobs run in batches.
    offset: u32,
    // Entries of the global-memory stack per invocation (its variant only).
    stack_stride: u32,
    // Always 0: the condition of `xm`'s select, which the compiler cannot see through.
    never: u32,
}

struct RayIn {
    ox: f32, oy: f32, oz: f32, t_min: f32,
    dx: f32, dy: f32, dz: f32, t_max: f32,
}

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> rays: array<RayIn>;
// (t, u, v, triangle) per ray; triangle = MISS where nothing is hit (MISS - 1: the stack overflowed).
@group(0) @binding(2) var<storage, read_write> hits: array<vec4<u32>>;
// nodes visited, box tests, leaves visited, triangle tests per ray (COUNTED only).
@group(0) @binding(3) var<storage, read_write> counts: array<vec4<u32>>;

// Whether products are kept from contraction (`xm`); off only in the benchmark's "fast" variant.
override EXACT: bool = true;
// Whether the per-ray counters are kept and written.
override COUNTED: bool = true;

var<private> NEVER: bool;
var<private> R_o: vec3<f32>;
var<private> R_d: vec3<f32>;
var<private> R_inv: vec3<f32>;
var<private> R_inv_far: vec3<f32>;
// Bit k set when the reciprocal direction on axis k is negative (-0 included).
var<private> R_neg: u32;
var<private> R_t_min: f32;
var<private> R_t_max: f32;
// nodes visited, box tests, leaves visited, triangle tests (core's RayCounters).
var<private> C: vec4<u32>;

fn count_nodes(n: u32) { if COUNTED { C.x += n; } }
fn count_boxes(n: u32) { if COUNTED { C.y += n; } }
fn count_leaves(n: u32) { if COUNTED { C.z += n; } }
fn count_tris(n: u32) { if COUNTED { C.w += n; } }

// a·b, rounded on its own. WGSL (like SPIR-V without NoContraction, which naga never emits) lets
// a compiler fuse a product into the sum that reads it; lavapipe does so in dot products, which
// changes results in the last place against the CPU. A select on a condition only known at run
// time hides the product from the fusing pattern; multiplying by a run-time 1.0 does not (the
// compiler reassociates it away; measured).
fn xm(a: f32, b: f32) -> f32 {
    return select(a * b, 0.0, NEVER);
}

// NaN found by its bits: a compiler may assume floats are never NaN (WGSL allows it), integers
// it must take as they are.
fn is_nan(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7fffffffu) > 0x7f800000u;
}

fn is_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

// max(acc, t) where a NaN t (0·inf: the ray lies in a slab plane) leaves acc as it is: Rust's
// f32::max, which core's slab test relies on (WGSL's max leaves a NaN operand undefined).
fn max_keep(acc: f32, t: f32) -> f32 {
    return select(max(acc, t), acc, is_nan(t));
}

fn min_keep(acc: f32, t: f32) -> f32 {
    return select(min(acc, t), acc, is_nan(t));
}

// core's slab::widen: t widened by SLACK of its magnitude towards +inf; -inf stays.
fn widen(t: f32) -> f32 {
    let w = t + abs(t) * SLACK;
    return select(max(w, t), t, is_nan(w));
}

// core's Ray::segment: a ray with a non-finite origin or direction, a zero direction or a NaN
// bound is born empty (t_min = inf, t_max = -inf), so no test can report a hit for it.
fn set_ray(o: vec3<f32>, d: vec3<f32>, t_min: f32, t_max: f32) {
    R_o = o;
    R_d = d;
    R_inv = vec3<f32>(1.0) / d;
    R_inv_far = R_inv * (1.0 + SLACK);
    let b = bitcast<vec3<u32>>(R_inv) >> vec3<u32>(31u);
    R_neg = b.x | (b.y << 1u) | (b.z << 2u);
    let valid = is_finite(o.x) && is_finite(o.y) && is_finite(o.z) && is_finite(d.x) && is_finite(d.y)
        && is_finite(d.z) && (d.x != 0.0 || d.y != 0.0 || d.z != 0.0) && !is_nan(t_min) && !is_nan(t_max);
    R_t_min = select(bitcast<f32>(0x7f800000u), t_min, valid);
    R_t_max = select(bitcast<f32>(0xff800000u), t_max, valid);
}

// core's OneRay::one_box: the clipped interval (enter, exit) of the box lo..hi, a hit when
// enter <= exit. Near and far planes by the reciprocal direction's sign; exits with the enlarged
// reciprocal; the running max and min in the order x, y, z, skipping NaN.
fn slab(lo: vec3<f32>, hi: vec3<f32>, t_min: f32, t_max: f32) -> vec2<f32> {
    let neg = vec3<bool>((R_neg & 1u) != 0u, (R_neg & 2u) != 0u, (R_neg & 4u) != 0u);
    let near = select(lo, hi, neg);
    let far = select(hi, lo, neg);
    let tn = (near - R_o) * R_inv;
    let tf = (far - R_o) * R_inv_far;
    let enter = max_keep(max_keep(max_keep(t_min, tn.x), tn.y), tn.z);
    let exit = min_keep(min_keep(min_keep(t_max, tf.x), tf.y), tf.z);
    return vec2<f32>(enter, exit);
}

// core's RayGen::ray through pixel (px, py)'s centre, operation by operation (glam's dot is
// (x·x' + y·y') + z·z'; normalize multiplies by 1/sqrt of it).
fn camera_ray(px: u32, py: u32) {
    let x = f32(px) + 0.5;
    let y = f32(py) + 0.5;
    let sx = xm(2.0 * x, P.inv_w) - 1.0;
    let sy = 1.0 - xm(2.0 * y, P.inv_h);
    let f = P.forward.xyz;
    let r = P.right.xyz;
    let u = P.up.xyz;
    let d = vec3<f32>(
        (f.x + xm(r.x, sx)) + xm(u.x, sy),
        (f.y + xm(r.y, sx)) + xm(u.y, sy),
        (f.z + xm(r.z, sx)) + xm(u.z, sy),
    );
    let len = sqrt((xm(d.x, d.x) + xm(d.y, d.y)) + xm(d.z, d.z));
    let dir = d * (1.0 / len);
    set_ray(P.origin.xyz, dir, 0.0, bitcast<f32>(0x7f800000u));
}
