// Boxes of the builders (lbvh.wgsl, ploc.wgsl): boxes as two corners of the triangles (`Tri`,
// nine floats: prelude.wgsl), and their unions with a min and max that are the same every time.

struct KBox { lo: array<f32, 3>, hi: array<f32, 3> }

// Min and max that pick the same operand every time (-0 and +0 compare equal): the verify pass
// compares boxes bit for bit and must see a repeated union unchanged.
fn fmin(a: f32, b: f32) -> f32 { return select(b, a, a < b); }
fn fmax(a: f32, b: f32) -> f32 { return select(b, a, a > b); }

fn tri_box(t: Tri) -> KBox {
    let v = t.v;
    return KBox(
        array<f32, 3>(fmin(fmin(v[0], v[3]), v[6]), fmin(fmin(v[1], v[4]), v[7]), fmin(fmin(v[2], v[5]), v[8])),
        array<f32, 3>(fmax(fmax(v[0], v[3]), v[6]), fmax(fmax(v[1], v[4]), v[7]), fmax(fmax(v[2], v[5]), v[8])),
    );
}

fn box_union(a: KBox, b: KBox) -> KBox {
    return KBox(
        array<f32, 3>(fmin(a.lo[0], b.lo[0]), fmin(a.lo[1], b.lo[1]), fmin(a.lo[2], b.lo[2])),
        array<f32, 3>(fmax(a.hi[0], b.hi[0]), fmax(a.hi[1], b.hi[1]), fmax(a.hi[2], b.hi[2])),
    );
}

fn empty_box() -> KBox {
    let inf = bitcast<f32>(0x7f800000u);
    return KBox(array<f32, 3>(inf, inf, inf), array<f32, 3>(-inf, -inf, -inf));
}

