// The paper's fallback, as core computes it: the three edge functions in double precision
// (every product of two floats is exact there), rounded to single.
fn edge_fallback(ax: f32, ay: f32, bx: f32, by: f32, cx: f32, cy: f32) -> vec3<f32> {
    let dax = f64(ax); let day = f64(ay);
    let dbx = f64(bx); let dby = f64(by);
    let dcx = f64(cx); let dcy = f64(cy);
    return vec3<f32>(f32(dcx * dby - dcy * dbx), f32(dax * dcy - day * dcx), f32(dbx * day - dby * dax));
}
