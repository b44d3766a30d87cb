// The entry points every node format shares: where the ray comes from (a camera's pixel or a
// list), the format's `walk`, and where its hit and counts go. The format defines `walk` and
// `prim_of`, and sets `best` (a leaf slot, or MISS), `best_u`, `best_v` and R_t_max.

var<private> best: u32;
var<private> best_u: f32;
var<private> best_v: f32;
// Set when a push would pass the stack's end: the host reports it (never expected: the stack is
// sized from the tree's depth).
var<private> overflow: bool;

// The most steps one walk may take: nodes visited (a CWBVH node counts its eight slots too),
// stack entries popped and triangles tested, every iteration of every loop of the walk. The same
// on every driver, and far below what any driver stops or a watchdog kills: lavapipe cuts a loop
// off silently after 65,535 iterations (which it counts three to a node), so a walk over a fan
// of 40,000 triangles in one box, a dump of fat boxes or a 100,000-deep chain came back as a miss.
// A walk that would pass it stops and says so (`unfinished`): the host finishes that ray on the
// CPU and says how many it finished (gpu/src/trace.rs).
const STEP_BUDGET: u32 = 16384u;
var<private> steps: u32;
var<private> unfinished: bool;

// Take `n` more steps, unless that passes the budget: then the walk is unfinished and must return.
fn spend(n: u32) -> bool {
    steps += n;
    if steps > STEP_BUDGET {
        unfinished = true;
        return false;
    }
    return true;
}

fn store(out: u32) {
    if unfinished {
        hits[out] = vec4<u32>(0u, 0u, 0u, MISS - 2u);
    } else if best == MISS {
        hits[out] = vec4<u32>(0u, 0u, 0u, select(MISS, MISS - 1u, overflow));
    } else {
        hits[out] = vec4<u32>(bitcast<u32>(R_t_max), bitcast<u32>(best_u), bitcast<u32>(best_v), prim_of(best));
    }
    if COUNTED {
        counts[out] = C;
    }
}

// One ray per pixel of rows P.offset.. of the frame, 8×8 pixels per workgroup (so a 32-lane warp
// is an 8×4 block of pixels, as the warp view groups them).
@compute @workgroup_size(8, 8)
fn trace_camera(@builtin(global_invocation_id) g: vec3<u32>, @builtin(workgroup_id) wg: vec3<u32>,
                @builtin(local_invocation_index) li: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    NEVER = P.never != 0u && EXACT;
    let px = g.x;
    let row = g.y;
    if px >= P.width || row >= P.count {
        return;
    }
    let out = row * P.width + px;
    stack_init(out);
    camera_ray(px, P.offset + row);
    walk();
    store(out);
}

// One ray of the list per invocation (the list holds this batch), 64 per workgroup.
@compute @workgroup_size(64)
fn trace_list(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32,
              @builtin(num_workgroups) nwg: vec3<u32>) {
    NEVER = P.never != 0u && EXACT;
    let i = (wg.y * nwg.x + wg.x) * 64u + li;
    if i >= P.count {
        return;
    }
    stack_init(i);
    let r = rays[i];
    set_ray(vec3<f32>(r.ox, r.oy, r.oz), vec3<f32>(r.dx, r.dy, r.dz), r.t_min, r.t_max);
    walk();
    store(i);
}
