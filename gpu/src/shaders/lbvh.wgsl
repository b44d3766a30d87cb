// The LBVH on the GPU: core's bvh::lbvh tree, built by Karras's parallel emission (Karras,
// "Maximizing Parallelism in the Construction of BVHs, Octrees, and k-d Trees", HPG 2012) over the
// distinct Morton codes, then laid out node for node as core lays out its tree. Kernels in order:
// bounds, codes (then the radix sort), run_flags, runs (runs of equal codes), karras, leaf_flags
// (where core's leaves start), boxes (bottom-up with atomic counters), verify (repairs what a
// relaxed atomic let a parent read early), emit (core's layout).

struct LParams {
    lo: vec4<f32>,
    scale: vec4<f32>,
    n: u32,
    max_leaf: u32,
    _pad0: u32,
    _pad1: u32,
}

// A node of the Karras tree: internal nodes 0..m-1, then the m runs of equal codes as its leaves.
// `parent` is the parent's index + 1 (0: the root); a range of sorted primitives [start, end).
struct KNode {
    parent: u32,
    start: u32,
    end: u32,
    left: u32,
    right: u32,
    axis: u32,
}

@group(0) @binding(0) var<uniform> LP: LParams;
@group(0) @binding(1) var<storage, read> tris: array<Tri>;
@group(0) @binding(2) var<storage, read_write> keys: array<u32>;
@group(0) @binding(3) var<storage, read_write> vals: array<u32>;
// 0..6: the centroids' bounds as ordered words (min x y z, max x y z); 6: ranges of equal codes
// cut in the middle (core's fallback splits); 7: boxes the verify pass changed.
@group(0) @binding(4) var<storage, read_write> stats: array<atomic<u32>>;
// Run flags, scanned: each sorted primitive's run; [n] the number of runs, m.
@group(0) @binding(5) var<storage, read_write> runid: array<u32>;
@group(0) @binding(6) var<storage, read_write> run_start: array<u32>;
@group(0) @binding(7) var<storage, read_write> run_code: array<u32>;
@group(0) @binding(8) var<storage, read_write> knodes: array<KNode>;
@group(0) @binding(9) var<storage, read_write> kboxes: array<KBox>;
@group(0) @binding(10) var<storage, read_write> counters: array<atomic<u32>>;
// Where core's leaves start (flags), scanned: leaves before each sorted primitive; [n] all.
@group(0) @binding(11) var<storage, read_write> leafp: array<u32>;
// core's BvhNode, 8 words each, in core's order.
@group(0) @binding(12) var<storage, read_write> out: array<array<u32, 8>>;

fn index(wg: vec3<u32>, nwg: vec3<u32>, lid: u32) -> u32 {
    return (wg.y * nwg.x + wg.x) * 64u + lid;
}

// Floats as words whose unsigned order is the floats' order, for atomicMin and atomicMax.
fn ordered(f: f32) -> u32 {
    let b = bitcast<u32>(f);
    return select(b | 0x80000000u, ~b, (b & 0x80000000u) != 0u);
}

// core's Aabb::from_points(tri).center(): (min + max) · 0.5.
fn centroid(t: Tri) -> vec3<f32> {
    let b = tri_box(t);
    return (vec3<f32>(b.lo[0], b.lo[1], b.lo[2]) + vec3<f32>(b.hi[0], b.hi[1], b.hi[2])) * 0.5;
}

@compute @workgroup_size(64)
fn bounds(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
          @builtin(local_invocation_index) lid: u32) {
    let i = index(wg, nwg, lid);
    if i >= LP.n {
        return;
    }
    let c = centroid(tris[i]);
    for (var k = 0u; k < 3u; k++) {
        atomicMin(&stats[k], ordered(c[k]));
        atomicMax(&stats[3u + k], ordered(c[k]));
    }
}

// core's lbvh::spread: bit i of the 10-bit v to bit 3i.
fn spread(v: u32) -> u32 {
    var x = v & 0x3ffu;
    x = (x | (x << 16u)) & 0x030000ffu;
    x = (x | (x << 8u)) & 0x0300f00fu;
    x = (x | (x << 4u)) & 0x030c30c3u;
    x = (x | (x << 2u)) & 0x09249249u;
    return x;
}

// core's lbvh::morton, its grid from the host (core's lbvh::grid): x on the top bit of each triple.
@compute @workgroup_size(64)
fn codes(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
         @builtin(local_invocation_index) lid: u32) {
    let i = index(wg, nwg, lid);
    if i >= LP.n {
        return;
    }
    let q = clamp((centroid(tris[i]) - LP.lo.xyz) * LP.scale.xyz, vec3<f32>(0.0), vec3<f32>(1023.0));
    let u = vec3<u32>(q);
    keys[i] = (spread(u.x) << 2u) | (spread(u.y) << 1u) | spread(u.z);
    vals[i] = i;
}

@compute @workgroup_size(64)
fn run_flags(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
             @builtin(local_invocation_index) lid: u32) {
    let i = index(wg, nwg, lid);
    if i > LP.n {
        return;
    }
    if i == LP.n {
        runid[i] = 0u;
        return;
    }
    // Every primitive starts a run of its own: equal codes are told apart by their places
    // (Karras's tie-break, `delta`), so the tree over them is built in parallel like the rest.
    runid[i] = 1u;
}

@compute @workgroup_size(64)
fn runs(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
        @builtin(local_invocation_index) lid: u32) {
    let i = index(wg, nwg, lid);
    if i >= LP.n {
        return;
    }
    run_start[runid[i]] = i;
    run_code[runid[i]] = keys[i];
    if i == 0u {
        run_start[runid[LP.n]] = LP.n;
    }
}

// The length of the common prefix of the keys of places i and j; -1 outside (Karras's δ). Equal
// codes are told apart by their places: 32 plus the common prefix of i and j (core's
// `morton::tie_split`), so a run of equal codes is the radix tree of its places.
fn delta(i: i32, j: i32, m: i32) -> i32 {
    if j < 0 || j >= m {
        return -1;
    }
    let x = run_code[u32(i)] ^ run_code[u32(j)];
    if x == 0u {
        return 32 + i32(countLeadingZeros(u32(i) ^ u32(j)));
    }
    return i32(countLeadingZeros(x));
}

@compute @workgroup_size(64)
fn karras(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
          @builtin(local_invocation_index) lid: u32) {
    let t = index(wg, nwg, lid);
    let m = runid[LP.n];
    if t < m {
        knodes[m - 1u + t].start = run_start[t];
        knodes[m - 1u + t].end = run_start[t + 1u];
    }
    if t + 1u >= m {
        return;
    }
    let i = i32(t);
    let mi = i32(m);
    // Direction of the node's range, its other end j, then the split (Karras 2012, Figure 4).
    let d = select(-1, 1, delta(i, i + 1, mi) > delta(i, i - 1, mi));
    let dmin = delta(i, i - d, mi);
    var lmax = 2;
    while delta(i, i + lmax * d, mi) > dmin {
        lmax *= 2;
    }
    var l = 0;
    for (var s = lmax / 2; s >= 1; s /= 2) {
        if delta(i, i + (l + s) * d, mi) > dmin {
            l += s;
        }
    }
    let j = i + l * d;
    let dnode = delta(i, j, mi);
    var split = 0;
    var div = 2;
    loop {
        let s = (l + div - 1) / div;
        if delta(i, i + (split + s) * d, mi) > dnode {
            split += s;
        }
        if s <= 1 {
            break;
        }
        div *= 2;
    }
    let gamma = i + split * d + min(d, 0);
    let first = u32(min(i, j));
    let last = u32(max(i, j));
    let g = u32(gamma);
    let left = select(g, m - 1u + g, first == g);
    let right = select(g + 1u, m - 1u + g + 1u, last == g + 1u);
    let x = run_code[first] ^ run_code[last];
    let bit = 31u - countLeadingZeros(x);
    knodes[t].start = run_start[first];
    knodes[t].end = run_start[last + 1u];
    knodes[t].left = left;
    knodes[t].right = right;
    // A range of equal codes is split by places, on axis 0, and counted as core counts it.
    knodes[t].axis = select(2u - bit % 3u, 0u, x == 0u);
    if x == 0u && last + 1u - first > LP.max_leaf {
        atomicAdd(&stats[6], 1u);
    }
    knodes[left].parent = t + 1u;
    knodes[right].parent = t + 1u;
}

fn parent_size(node: KNode) -> u32 {
    if node.parent == 0u {
        return 0xffffffffu;
    }
    let p = knodes[node.parent - 1u];
    return p.end - p.start;
}

// core's leaves: a range of at most max_leaf primitives whose parent's is larger (or the root).
// (Every leaf of the Karras tree is one primitive, so every range fits somewhere.)
@compute @workgroup_size(64)
fn leaf_flags(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
              @builtin(local_invocation_index) lid: u32) {
    let x = index(wg, nwg, lid);
    let m = runid[LP.n];
    if x >= 2u * m - 1u {
        return;
    }
    let node = knodes[x];
    let size = node.end - node.start;
    if size <= LP.max_leaf && parent_size(node) > LP.max_leaf {
        leafp[node.start] = 1u;
    }
}

fn range_box(start: u32, end: u32) -> KBox {
    var b = empty_box();
    for (var i = start; i < end; i++) {
        b = box_union(b, tri_box(tris[vals[i]]));
    }
    return b;
}

// Each run's box, then up the tree: the second child to arrive at a parent makes its box.
@compute @workgroup_size(64)
fn boxes(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
         @builtin(local_invocation_index) lid: u32) {
    let r = index(wg, nwg, lid);
    let m = runid[LP.n];
    if r >= m {
        return;
    }
    var cur = m - 1u + r;
    let node = knodes[cur];
    kboxes[cur] = range_box(node.start, node.end);
    loop {
        let p = knodes[cur].parent;
        if p == 0u {
            break;
        }
        if atomicAdd(&counters[p - 1u], 1u) == 0u {
            break;
        }
        let pn = knodes[p - 1u];
        kboxes[p - 1u] = box_union(kboxes[pn.left], kboxes[pn.right]);
        cur = p - 1u;
    }
}

fn same(a: KBox, b: KBox) -> bool {
    var s = true;
    for (var k = 0u; k < 3u; k++) {
        s = s && bitcast<u32>(a.lo[k]) == bitcast<u32>(b.lo[k]) && bitcast<u32>(a.hi[k]) == bitcast<u32>(b.hi[k]);
    }
    return s;
}

// WGSL's atomics are relaxed: the second child at a parent may read its sibling's box before that
// box's writes are visible. Every interior box is checked against its children here, after the
// dispatch boundary made all writes visible, and the host repeats this until nothing changes.
@compute @workgroup_size(64)
fn verify(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
          @builtin(local_invocation_index) lid: u32) {
    let k = index(wg, nwg, lid);
    let m = runid[LP.n];
    if k + 1u >= m {
        return;
    }
    let node = knodes[k];
    let b = box_union(kboxes[node.left], kboxes[node.right]);
    if !same(b, kboxes[k]) {
        kboxes[k] = b;
        atomicAdd(&stats[7], 1u);
    }
}

fn leaves_in(start: u32, end: u32) -> u32 {
    return leafp[end] - leafp[start];
}

fn leaves_of(x: u32) -> u32 {
    return leaves_in(knodes[x].start, knodes[x].end);
}

fn write(pos: u32, b: KBox, index: u32, count_axis: u32) {
    out[pos] = array<u32, 8>(bitcast<u32>(b.lo[0]), bitcast<u32>(b.lo[1]), bitcast<u32>(b.lo[2]),
        bitcast<u32>(b.hi[0]), bitcast<u32>(b.hi[1]), bitcast<u32>(b.hi[2]), index, count_axis);
}

// core's layout (bvh::subtree: each node's children a pair, the left subtree's pairs before the
// right's): a node's children sit at cpos and cpos + 1; the left child's children at cpos + 2,
// the right child's at cpos + 1 + (nodes of the left subtree) = cpos + 2·(leaves under the left).
// So cpos is 1 plus, for each edge down from the root, 2 where it goes left and 2·(leaves under
// the left sibling) where it goes right: each node climbs to the root to add them up.
@compute @workgroup_size(64)
fn emit(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
        @builtin(local_invocation_index) lid: u32) {
    let x = index(wg, nwg, lid);
    let m = runid[LP.n];
    if x >= 2u * m - 1u {
        return;
    }
    let node = knodes[x];
    let size = node.end - node.start;
    let interior = size > LP.max_leaf;
    if !interior && parent_size(node) <= LP.max_leaf {
        return;
    }
    var pos = 0u;
    var cpos = 1u;
    if node.parent != 0u {
        let pn = knodes[node.parent - 1u];
        let side = select(1u, 0u, pn.left == x);
        var sum = 1u;
        var cur = node.parent - 1u;
        loop {
            let q = knodes[cur].parent;
            if q == 0u {
                break;
            }
            let qn = knodes[q - 1u];
            sum += select(2u * leaves_of(qn.left), 2u, qn.left == cur);
            cur = q - 1u;
        }
        pos = sum + side;
        cpos = sum + select(2u * leaves_of(pn.left), 2u, side == 0u);
    }
    if !interior {
        write(pos, kboxes[x], node.start, size);
    } else {
        write(pos, kboxes[x], cpos, node.axis << 16u);
    }
}
