// One pass of a stable LSD radix sort of (key, value) pairs, four bits of the key at a time
// (Merrill & Grimshaw, "High Performance and Scalable Radix Sorting", 2011, without their
// decoupled look-back): each tile of 4096 pairs counts its digits (`histogram`), the counts
// [digit][tile] are scanned into each tile's first slot per digit (scan.wgsl), and `scatter`
// moves the pairs there, 256 at a time in order, each ranked among the equal digits before it
// by a scan of one-hot counters, so equal keys keep their order: the sort is stable.

struct SortParams {
    n: u32,
    shift: u32,
    tiles: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> SO: SortParams;
@group(0) @binding(1) var<storage, read> keys_in: array<u32>;
@group(0) @binding(2) var<storage, read> vals_in: array<u32>;
// Digit counts per tile, [digit][tile]; after the scan, where each tile's digit starts.
@group(0) @binding(3) var<storage, read_write> offsets: array<u32>;
@group(0) @binding(4) var<storage, read_write> keys_out: array<u32>;
@group(0) @binding(5) var<storage, read_write> vals_out: array<u32>;

const TILE: u32 = 4096u;
const ROUNDS: u32 = 16u;

var<workgroup> counts: array<atomic<u32>, 16>;
// Per invocation, eight words of two 16-bit counters: one per digit.
var<workgroup> packed: array<u32, 2048>;
// Pairs of this tile placed so far, per digit.
var<workgroup> running: array<u32, 16>;

@compute @workgroup_size(256)
fn histogram(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
             @builtin(local_invocation_index) lid: u32) {
    let tile = wg.y * nwg.x + wg.x;
    if tile >= SO.tiles {
        return;
    }
    if lid < 16u {
        atomicStore(&counts[lid], 0u);
    }
    workgroupBarrier();
    for (var r = 0u; r < ROUNDS; r++) {
        let i = tile * TILE + r * 256u + lid;
        if i < SO.n {
            atomicAdd(&counts[(keys_in[i] >> SO.shift) & 15u], 1u);
        }
    }
    workgroupBarrier();
    if lid < 16u {
        offsets[lid * SO.tiles + tile] = atomicLoad(&counts[lid]);
    }
}

@compute @workgroup_size(256)
fn scatter(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
           @builtin(local_invocation_index) lid: u32) {
    let tile = wg.y * nwg.x + wg.x;
    if tile >= SO.tiles {
        return;
    }
    if lid < 16u {
        running[lid] = 0u;
    }
    workgroupBarrier();
    for (var r = 0u; r < ROUNDS; r++) {
        if tile * TILE + r * 256u >= SO.n {
            break;
        }
        let i = tile * TILE + r * 256u + lid;
        let valid = i < SO.n;
        var key = 0u;
        var val = 0u;
        if valid {
            key = keys_in[i];
            val = vals_in[i];
        }
        let d = (key >> SO.shift) & 15u;
        let word = d >> 1u;
        let sh = (d & 1u) * 16u;
        for (var w = 0u; w < 8u; w++) {
            packed[lid * 8u + w] = select(0u, 1u << sh, valid && w == word);
        }
        workgroupBarrier();
        for (var off = 1u; off < 256u; off <<= 1u) {
            var add: array<u32, 8>;
            let src = select(0u, lid - off, lid >= off) * 8u;
            for (var w = 0u; w < 8u; w++) {
                add[w] = select(0u, packed[src + w], lid >= off);
            }
            workgroupBarrier();
            for (var w = 0u; w < 8u; w++) {
                packed[lid * 8u + w] += add[w];
            }
            workgroupBarrier();
        }
        if valid {
            let rank = ((packed[lid * 8u + word] >> sh) & 0xffffu) - 1u;
            let dest = offsets[d * SO.tiles + tile] + running[d] + rank;
            keys_out[dest] = key;
            vals_out[dest] = val;
        }
        workgroupBarrier();
        if lid < 16u {
            running[lid] += (packed[255u * 8u + (lid >> 1u)] >> ((lid & 1u) * 16u)) & 0xffffu;
        }
        workgroupBarrier();
    }
}
