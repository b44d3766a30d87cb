// An adapter without 64-bit floats keeps the single-precision edge functions. A zero stays zero,
// and the sign rule takes a zero as inside for both triangles of a shared edge: a ray through it
// still hits (no gap), but where the CPU's doubles pick one of two triangles at the same distance
// this may pick the other.
fn edge_fallback(ax: f32, ay: f32, bx: f32, by: f32, cx: f32, cy: f32) -> vec3<f32> {
    return vec3<f32>(xm(cx, by) - xm(cy, bx), xm(ax, cy) - xm(ay, cx), xm(bx, ay) - xm(by, ax));
}
