// The CWBVH walk (Ylitie, Karras & Laine 2017, §4), step for step what gpu/src/cwbvh/walk.rs does
// on the CPU: at a node all eight children's quantised boxes are decoded and tested; hit leaves
// are tested at once, nearest octant first; hit interior children form a group, a bit mask over
// the slots in the ray's octant order, whose first child is entered and whose rest is pushed as
// one stack entry (child base, bits << 8 | interior mask).

// An 80-byte node as 20 words (gpu/src/cwbvh/mod.rs documents the bytes).
struct CNode { w: array<u32, 20> }
// `Tri`: prelude.wgsl; `test_leaf` and `prim_of`: leaf.wgsl.

@group(0) @binding(5) var<storage, read> cnodes: array<CNode>;
// (first triangle, count) per leaf.
@group(0) @binding(6) var<storage, read> leaves: array<vec2<u32>>;
@group(0) @binding(7) var<storage, read> tris: array<Tri>;
@group(0) @binding(8) var<storage, read> prim_ids: array<u32>;

// Byte k (0 = lowest) of the 8-byte field that starts at word w, for slot s.
fn slot_byte(n: ptr<function, CNode>, w: u32, s: u32) -> u32 {
    return ((*n).w[w + (s >> 2u)] >> (8u * (s & 3u))) & 0xffu;
}

fn walk() {
    start_walk();
    var limit = widen(R_t_max);
    count_boxes(1u);
    let root = slab(P.root_lo.xyz, P.root_hi.xyz, R_t_min, limit);
    if !(root.x <= root.y) || P.root_lo.w == 0.0 {
        return;
    }
    prepare_shear();
    let oct = R_neg;
    var len = 0u;
    var cur = 0u;
    loop {
        // The node and its eight slots.
        if !spend(9u) {
            return;
        }
        var n = cnodes[cur];
        count_nodes(1u);
        let p = vec3<f32>(bitcast<f32>(n.w[0]), bitcast<f32>(n.w[1]), bitcast<f32>(n.w[2]));
        let ew = n.w[3];
        let scale = vec3<f32>(bitcast<f32>((ew & 0xffu) << 23u), bitcast<f32>(((ew >> 8u) & 0xffu) << 23u),
                              bitcast<f32>(((ew >> 16u) & 0xffu) << 23u));
        let imask = ew >> 24u;
        var inner = 0u;
        var leaf_hits = 0u;
        var valid = 0u;
        for (var s = 0u; s < 8u; s++) {
            if slot_byte(&n, 6u, s) == 0u {
                continue;
            }
            valid += 1u;
            let q_lo = vec3<f32>(f32(slot_byte(&n, 8u, s)), f32(slot_byte(&n, 10u, s)), f32(slot_byte(&n, 12u, s)));
            let q_hi = vec3<f32>(f32(slot_byte(&n, 14u, s)), f32(slot_byte(&n, 16u, s)), f32(slot_byte(&n, 18u, s)));
            // q·scale is exact (8 bits times a power of two), so one rounding, fused or not.
            let t = slab(p + q_lo * scale, p + q_hi * scale, R_t_min, limit);
            if t.x <= t.y {
                let bit = 1u << (s ^ oct);
                if ((imask >> s) & 1u) != 0u {
                    inner |= bit;
                } else {
                    leaf_hits |= bit;
                }
            }
        }
        count_boxes(valid);
        while leaf_hits != 0u {
            if !spend(1u) {
                return;
            }
            let s = firstTrailingBit(leaf_hits) ^ oct;
            leaf_hits &= leaf_hits - 1u;
            let rec = leaves[n.w[5] + (slot_byte(&n, 6u, s) & 0x1fu)];
            count_leaves(1u);
            test_leaf(rec.x, rec.y);
            if unfinished {
                return;
            }
            limit = widen(R_t_max);
        }
        var base = n.w[4];
        var bits = inner;
        var group_imask = imask;
        if bits == 0u {
            if len == 0u {
                break;
            }
            len -= 1u;
            let e = stack_get(len);
            base = e.x;
            bits = e.y >> 8u;
            group_imask = e.y & 0xffu;
        }
        let s = firstTrailingBit(bits) ^ oct;
        bits &= bits - 1u;
        cur = base + countOneBits(group_imask & ((1u << s) - 1u));
        if bits != 0u {
            if len >= STACK_SIZE {
                overflow = true;
                return;
            }
            stack_set(len, vec2<u32>(base, (bits << 8u) | group_imask));
            len += 1u;
        }
    }
}
