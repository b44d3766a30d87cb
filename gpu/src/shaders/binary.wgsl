// The binary BVH's walk: core's bvh::traverse::walk, step by step and count by count. Ordered
// stack traversal (pbrt-v4 §7.3.5): both children's boxes tested at an interior node, the near
// one entered, the far one pushed with its entry distance and dropped when popped beyond the
// closest hit so far. Near is the smaller entry distance (BY_DISTANCE) or the handout's rule, the
// direction's sign on the node's split axis.

override BY_DISTANCE: bool = true;

// core's BvhNode, 32 bytes: the box's planes, then the left child (interior) or first triangle
// (leaf), then the triangle count (0: interior) in the low 16 bits and the split axis above.
struct Node {
    lo_x: f32, lo_y: f32, lo_z: f32,
    hi_x: f32, hi_y: f32, hi_z: f32,
    index: u32,
    info: u32,
}

// `Tri`, a triangle's three vertices in leaf order: prelude.wgsl; `test_leaf` and `prim_of`: leaf.wgsl.

@group(0) @binding(5) var<storage, read> nodes: array<Node>;
@group(0) @binding(6) var<storage, read> tris: array<Tri>;
@group(0) @binding(7) var<storage, read> prim_ids: array<u32>;

fn node_slab(i: u32, t_min: f32, limit: f32) -> vec2<f32> {
    let n = nodes[i];
    return slab(vec3<f32>(n.lo_x, n.lo_y, n.lo_z), vec3<f32>(n.hi_x, n.hi_y, n.hi_z), t_min, limit);
}

fn walk() {
    start_walk();
    // The closest hit so far, widened: what boxes and stack entries are compared with.
    var limit = widen(R_t_max);
    count_boxes(1u);
    let root = node_slab(0u, R_t_min, limit);
    if !(root.x <= root.y) {
        return;
    }
    prepare_shear();
    var len = 0u;
    var current = 0u;
    loop {
        if !spend(1u) {
            return;
        }
        let node = nodes[current];
        count_nodes(1u);
        let leaf_count = node.info & 0xffffu;
        if leaf_count != 0u {
            count_leaves(1u);
            test_leaf(node.index, leaf_count);
            if unfinished {
                return;
            }
            limit = widen(R_t_max);
        } else {
            let left = node.index;
            count_boxes(2u);
            let l = node_slab(left, R_t_min, limit);
            let r = node_slab(left + 1u, R_t_min, limit);
            let lh = l.x <= l.y;
            let rh = r.x <= r.y;
            if lh && rh {
                var right_first: bool;
                if BY_DISTANCE {
                    right_first = r.x < l.x;
                } else {
                    right_first = ((R_neg >> ((node.info >> 16u) & 3u)) & 1u) != 0u;
                }
                let near = select(left, left + 1u, right_first);
                let far = select(left + 1u, left, right_first);
                let far_t = select(r.x, l.x, right_first);
                if len >= STACK_SIZE {
                    overflow = true;
                    return;
                }
                stack_set(len, vec2<u32>(far, bitcast<u32>(far_t)));
                len += 1u;
                current = near;
                continue;
            }
            if lh {
                current = left;
                continue;
            }
            if rh {
                current = left + 1u;
                continue;
            }
        }
        // The next entry that can still hold a hit nearer than the best so far.
        var found = false;
        loop {
            if len == 0u {
                break;
            }
            if !spend(1u) {
                return;
            }
            len -= 1u;
            let e = stack_get(len);
            if bitcast<f32>(e.y) <= limit {
                current = e.x;
                found = true;
                break;
            }
        }
        if !found {
            break;
        }
    }
}

