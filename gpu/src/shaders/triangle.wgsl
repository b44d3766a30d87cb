// core's geometry::triangle::Watertight, operation by operation: Woop, Benthin & Wald,
// "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013. The ray is sheared to point along +z
// (three rows, built from a table of the six axis cases as core's `prepare` does), the 2D edge
// functions are evaluated, and recomputed in double precision when one is exactly zero
// (`edge_fallback`, substituted per adapter: doubles where it has SHADER_F64).

var<private> S_rx: vec3<f32>;
var<private> S_ry: vec3<f32>;
var<private> S_rz: vec3<f32>;

fn unit(k: u32) -> vec3<f32> {
    return vec3<f32>(select(0.0, 1.0, k == 0u), select(0.0, 1.0, k == 1u), select(0.0, 1.0, k == 2u));
}

fn component(v: vec3<f32>, k: u32) -> f32 {
    return select(select(v.z, v.y, k == 1u), v.x, k == 0u);
}

// The shear of the current ray (core's Watertight::prepare).
fn prepare_shear() {
    let d = R_d;
    let a = abs(d);
    let x_largest = a.x >= a.y && a.x >= a.z;
    let kz0 = select(2u - select(0u, 1u, a.y >= a.z), 0u, x_largest);
    // AXES[2·kz + (d[kz] < 0)], as [kx, ky, kz]: [[1,2,0],[2,1,0],[2,0,1],[0,2,1],[0,1,2],[1,0,2]].
    let row = 2u * kz0 + select(0u, 1u, component(d, kz0) < 0.0);
    var kx: u32; var ky: u32;
    switch row {
        case 0u: { kx = 1u; ky = 2u; }
        case 1u: { kx = 2u; ky = 1u; }
        case 2u: { kx = 2u; ky = 0u; }
        case 3u: { kx = 0u; ky = 2u; }
        case 4u: { kx = 0u; ky = 1u; }
        default: { kx = 1u; ky = 0u; }
    }
    let dz = component(d, kz0);
    let sx = component(d, kx) / dz;
    let sy = component(d, ky) / dz;
    let sz = 1.0 / dz;
    let rz_axis = unit(kz0);
    S_rx = unit(kx) - rz_axis * sx;
    S_ry = unit(ky) - rz_axis * sy;
    S_rz = rz_axis * sz;
}

// glam's dot, (x·x' + y·y') + z·z', each product rounded on its own.
fn dotx(a: vec3<f32>, r: vec3<f32>) -> f32 {
    return (xm(a.x, r.x) + xm(a.y, r.y)) + xm(a.z, r.z);
}

// Which test the walk runs: core's TriangleTest in the order of its list (TriangleTest::ALL):
// 0 Watertight, 1 MollerTrumbore, 2 MollerTrumboreStored.
override TEST: u32 = 0u;

// The hit of the triangle v0, v1, v2 within [R_t_min, R_t_max): (t, u, v) with u weighting v1
// and v weighting v2, and w = 1 for a hit, 0 for a miss.
fn intersect(v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>) -> vec4<f32> {
    if TEST == 1u {
        return intersect_mt(v0, v1, v2);
    }
    if TEST == 2u {
        return intersect_mt_stored(v0, v1, v2);
    }
    return intersect_watertight(v0, v1, v2);
}

// glam's cross, each product rounded on its own.
fn crossx(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(xm(a.y, b.z) - xm(b.y, a.z), xm(a.z, b.x) - xm(b.z, a.x), xm(a.x, b.y) - xm(b.x, a.y));
}

// core's geometry::triangle::MollerTrumbore, operation by operation: Möller & Trumbore, "Fast,
// Minimum Storage Ray/Triangle Intersection", JGT 2(1), 1997 (the handout's test).
fn intersect_mt(v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>) -> vec4<f32> {
    let d = R_d;
    let e1 = v1 - v0;
    let e2 = v2 - v0;
    let pv = crossx(d, e2);
    let det = dotx(e1, pv);
    // |det| = |d|·|e1 × e2|·|cos|; rejected below 1e-7 of its largest possible value.
    let scale = xm(xm(sqrt(dotx(d, d)), sqrt(dotx(e1, e1))), sqrt(dotx(e2, e2)));
    if is_nan(det) || !(abs(det) > xm(1e-7, scale)) {
        return vec4<f32>(0.0);
    }
    let inv_det = 1.0 / det;
    let s = R_o - v0;
    let u = xm(dotx(s, pv), inv_det);
    if is_nan(u) || !(u >= 0.0 && u <= 1.0) {
        return vec4<f32>(0.0);
    }
    let q = crossx(s, e1);
    let v = xm(dotx(d, q), inv_det);
    if v < 0.0 || u + v > 1.0 || is_nan(v) {
        return vec4<f32>(0.0);
    }
    let t = xm(dotx(e2, q), inv_det);
    if t >= R_t_min && t < R_t_max {
        return vec4<f32>(t, u, v, 1.0);
    }
    return vec4<f32>(0.0);
}

// core's geometry::stored_triangle, operation by operation: Möller–Trumbore on the edges
// e1 = v0 − v1, e2 = v2 − v0 and the normal e1 × e2 (Embree's form), made here from the vertices
// as core makes its stored leaves; the signs those of a positive denominator, then one division.
fn intersect_mt_stored(v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>) -> vec4<f32> {
    let d = R_d;
    let e1 = v0 - v1;
    let e2 = v2 - v0;
    let ng = crossx(e1, e2);
    let c = v0 - R_o;
    let r = crossx(d, c);
    let den = dotx(ng, d);
    let sign = bitcast<u32>(den) & 0x80000000u;
    let abs_den = abs(den);
    let u = bitcast<f32>(bitcast<u32>(dotx(r, e2)) ^ sign);
    let v = bitcast<f32>(bitcast<u32>(dotx(r, e1)) ^ sign);
    // NaN fails core's comparisons; here it is found by its bits (the compiler may assume none).
    if is_nan(den) || is_nan(u) || is_nan(v) || !(den != 0.0 && u >= 0.0 && v >= 0.0 && u + v <= abs_den) {
        return vec4<f32>(0.0);
    }
    let rcp = 1.0 / abs_den;
    let t = xm(bitcast<f32>(bitcast<u32>(dotx(ng, c)) ^ sign), rcp);
    if t >= R_t_min && t < R_t_max {
        return vec4<f32>(t, xm(u, rcp), xm(v, rcp), 1.0);
    }
    return vec4<f32>(0.0);
}

// core's Watertight test (above).
fn intersect_watertight(v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>) -> vec4<f32> {
    let a = v0 - R_o;
    let b = v1 - R_o;
    let c = v2 - R_o;
    let ax = dotx(a, S_rx);
    let ay = dotx(a, S_ry);
    let bx = dotx(b, S_rx);
    let by = dotx(b, S_ry);
    let cx = dotx(c, S_rx);
    let cy = dotx(c, S_ry);
    var u = xm(cx, by) - xm(cy, bx);
    var v = xm(ax, cy) - xm(ay, cx);
    var w = xm(bx, ay) - xm(by, ax);
    if u == 0.0 || v == 0.0 || w == 0.0 {
        let e = edge_fallback(ax, ay, bx, by, cx, cy);
        u = e.x;
        v = e.y;
        w = e.z;
    }
    // Inside when all three share a sign (both faces are hit).
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return vec4<f32>(0.0);
    }
    let det = (u + v) + w;
    if det == 0.0 {
        return vec4<f32>(0.0);
    }
    let t_scaled = (xm(u, dotx(a, S_rz)) + xm(v, dotx(b, S_rz))) + xm(w, dotx(c, S_rz));
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;
    // Written as the accepting test: a NaN t fails it whatever a compiler assumes about NaN.
    if t >= R_t_min && t < R_t_max {
        return vec4<f32>(t, v * inv_det, w * inv_det, 1.0);
    }
    return vec4<f32>(0.0);
}
