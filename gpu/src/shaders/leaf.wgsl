// What every walk does the same way (each declares `tris` and `prim_ids` at its own bindings).

// The mesh's number of the triangle in leaf slot i.
fn prim_of(i: u32) -> u32 {
    return prim_ids[i];
}

// core's test_triangles: every triangle of the leaf in order, each nearer hit shrinking t_max.
fn test_leaf(first: u32, count: u32) {
    if !spend(count) {
        return;
    }
    for (var k = 0u; k < count; k++) {
        let i = first + k;
        let t = tris[i].v;
        let h = intersect(vec3<f32>(t[0], t[1], t[2]), vec3<f32>(t[3], t[4], t[5]), vec3<f32>(t[6], t[7], t[8]));
        if h.w != 0.0 {
            R_t_max = h.x;
            best = i;
            best_u = h.y;
            best_v = h.z;
        }
    }
    count_tris(count);
}

// A walk's state before its first step: no hit, nothing counted, no overflow, not cut short.
fn start_walk() {
    best = MISS;
    C = vec4<u32>(0u);
    overflow = false;
    steps = 0u;
    unfinished = false;
}
