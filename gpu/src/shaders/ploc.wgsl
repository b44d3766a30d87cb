// One round of PLOC (Meister & Bittner, "Parallel Locally-Ordered Clustering for Bounding Volume
// Hierarchy Construction", TVCG 2018) as core's bvh::ploc runs it, so the GPU finds the same
// pairs: each cluster's nearest neighbour within `radius` each side in Morton order (smallest
// union area; ties to the nearer, and at equal distance d to the one after it in an even block of
// d, before it in an odd one), mutual pairs merged in the first one's place, the rest kept in order.

struct PParams {
    count: u32,
    radius: u32,
    n: u32,
    // Always 0: the condition of `xm`'s select (see trace's common.wgsl).
    never: u32,
}

// A node of the clustered tree: a primitive (left = LEAF, right its sorted slot) or a merge.
struct Cluster {
    lo: array<f32, 3>,
    hi: array<f32, 3>,
    left: u32,
    right: u32,
}

const LEAF: u32 = 0xffffffffu;

@group(0) @binding(0) var<uniform> PP: PParams;
@group(0) @binding(1) var<storage, read> tris: array<Tri>;
@group(0) @binding(2) var<storage, read> vals: array<u32>;
@group(0) @binding(3) var<storage, read_write> boxes_in: array<KBox>;
@group(0) @binding(4) var<storage, read_write> clusters_in: array<u32>;
@group(0) @binding(5) var<storage, read_write> nearest: array<u32>;
// 1 where a cluster stays (kept or the first of a pair), then scanned: its place in the next round.
@group(0) @binding(6) var<storage, read_write> keep: array<u32>;
@group(0) @binding(7) var<storage, read_write> boxes_out: array<KBox>;
@group(0) @binding(8) var<storage, read_write> clusters_out: array<u32>;
@group(0) @binding(9) var<storage, read_write> nodes: array<Cluster>;
// 0: a mutual pair was found this round; 1: nodes made so far.
@group(0) @binding(10) var<storage, read_write> stats: array<atomic<u32>>;

fn index(wg: vec3<u32>, nwg: vec3<u32>, lid: u32) -> u32 {
    return (wg.y * nwg.x + wg.x) * 64u + lid;
}

fn xm(a: f32, b: f32) -> f32 {
    return select(a * b, 0.0, PP.never != 0u);
}

// core's Aabb::area of the union: e = max(max - min, 0), 2·((ex·ey + ey·ez) + ez·ex).
fn union_area(a: KBox, b: KBox) -> f32 {
    let u = box_union(a, b);
    let e = max(vec3<f32>(u.hi[0] - u.lo[0], u.hi[1] - u.lo[1], u.hi[2] - u.lo[2]), vec3<f32>(0.0));
    return 2.0 * ((xm(e.x, e.y) + xm(e.y, e.z)) + xm(e.z, e.x));
}

@compute @workgroup_size(64)
fn init(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
        @builtin(local_invocation_index) lid: u32) {
    let i = index(wg, nwg, lid);
    if i >= PP.n {
        return;
    }
    let b = tri_box(tris[vals[i]]);
    boxes_in[i] = b;
    clusters_in[i] = i;
    nodes[i] = Cluster(b.lo, b.hi, LEAF, i);
}

// (distance, away) of candidate j for cluster i: smaller is preferred at equal area.
fn rank(i: u32, j: u32) -> u32 {
    let d = select(i - j, j - i, j > i);
    let toward = select((j < i), (j > i), ((i / d) & 1u) == 0u);
    return 2u * d + select(1u, 0u, toward);
}

@compute @workgroup_size(64)
fn nearest_neighbours(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
                      @builtin(local_invocation_index) lid: u32) {
    let i = index(wg, nwg, lid);
    if i >= PP.count {
        return;
    }
    let bi = boxes_in[i];
    var best_a = 0.0;
    var best = 0xffffffffu;
    let lo = i - min(i, PP.radius);
    let hi = min(PP.count - 1u, i + PP.radius);
    for (var j = lo; j <= hi; j++) {
        if j == i {
            continue;
        }
        let a = union_area(bi, boxes_in[j]);
        if best == 0xffffffffu || a < best_a || (a == best_a && rank(i, j) < rank(i, best)) {
            best_a = a;
            best = j;
        }
    }
    nearest[i] = best;
}

@compute @workgroup_size(64)
fn mutual(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
          @builtin(local_invocation_index) lid: u32) {
    let i = index(wg, nwg, lid);
    if i >= PP.count {
        return;
    }
    if nearest[nearest[i]] == i {
        atomicOr(&stats[0], 1u);
    }
}

@compute @workgroup_size(64)
fn keep_flags(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
              @builtin(local_invocation_index) lid: u32) {
    let i = index(wg, nwg, lid);
    if i > PP.count {
        return;
    }
    if i == PP.count {
        keep[i] = 0u;
        return;
    }
    let j = nearest[i];
    keep[i] = select(1u, 0u, nearest[j] == i && i > j);
}

@compute @workgroup_size(64)
fn compact(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
           @builtin(local_invocation_index) lid: u32) {
    let i = index(wg, nwg, lid);
    if i >= PP.count {
        return;
    }
    let j = nearest[i];
    let pair = nearest[j] == i;
    if pair && i > j {
        return;
    }
    let pos = keep[i];
    if pair {
        // Node numbers in any order within a round: the tree, not the numbering, is what counts,
        // and a merge's children are always from earlier rounds (smaller numbers).
        let id = atomicAdd(&stats[1], 1u);
        let b = box_union(boxes_in[i], boxes_in[j]);
        nodes[id] = Cluster(b.lo, b.hi, clusters_in[i], clusters_in[j]);
        clusters_out[pos] = id;
        boxes_out[pos] = b;
    } else {
        clusters_out[pos] = clusters_in[i];
        boxes_out[pos] = boxes_in[i];
    }
}
