// Exclusive prefix sums of a u32 array in place, in three passes (a scan of each block of 4096,
// a scan of the block totals in one workgroup, the block offsets added back): the "reduce, scan,
// propagate" form of Merrill & Garland's single-pass scan without its look-back, which WGSL's
// relaxed atomics cannot order.

struct ScanParams {
    len: u32,
    blocks: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> SP: ScanParams;
@group(0) @binding(1) var<storage, read_write> data: array<u32>;
@group(0) @binding(2) var<storage, read_write> sums: array<u32>;

const ITEMS: u32 = 16u;
const BLOCK: u32 = 4096u;

var<workgroup> shared_sums: array<u32, 256>;

// The sum of the values of the invocations before `lid` (Hillis & Steele's scan).
fn workgroup_exclusive(lid: u32, v: u32) -> u32 {
    shared_sums[lid] = v;
    workgroupBarrier();
    for (var off = 1u; off < 256u; off <<= 1u) {
        var add = 0u;
        if lid >= off {
            add = shared_sums[lid - off];
        }
        workgroupBarrier();
        shared_sums[lid] += add;
        workgroupBarrier();
    }
    return shared_sums[lid] - v;
}

@compute @workgroup_size(256)
fn scan_blocks(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
               @builtin(local_invocation_index) lid: u32) {
    let block = wg.y * nwg.x + wg.x;
    if block >= SP.blocks {
        return;
    }
    let base = block * BLOCK + lid * ITEMS;
    var vals: array<u32, 16>;
    var sum = 0u;
    for (var k = 0u; k < ITEMS; k++) {
        let i = base + k;
        var v = 0u;
        if i < SP.len {
            v = data[i];
        }
        vals[k] = v;
        sum += v;
    }
    let excl = workgroup_exclusive(lid, sum);
    var run = excl;
    for (var k = 0u; k < ITEMS; k++) {
        let i = base + k;
        if i < SP.len {
            data[i] = run;
        }
        run += vals[k];
    }
    if lid == 255u {
        sums[block] = run;
    }
}

@compute @workgroup_size(256)
fn scan_sums(@builtin(local_invocation_index) lid: u32) {
    let per = (SP.blocks + 255u) / 256u;
    let base = lid * per;
    var sum = 0u;
    for (var k = 0u; k < per; k++) {
        if base + k < SP.blocks {
            sum += sums[base + k];
        }
    }
    var run = workgroup_exclusive(lid, sum);
    for (var k = 0u; k < per; k++) {
        if base + k < SP.blocks {
            let v = sums[base + k];
            sums[base + k] = run;
            run += v;
        }
    }
}

@compute @workgroup_size(256)
fn add_sums(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
            @builtin(local_invocation_index) lid: u32) {
    let block = wg.y * nwg.x + wg.x;
    if block >= SP.blocks {
        return;
    }
    let offset = sums[block];
    for (var k = 0u; k < ITEMS; k++) {
        let i = block * BLOCK + k * 256u + lid;
        if i < SP.len {
            data[i] += offset;
        }
    }
}
