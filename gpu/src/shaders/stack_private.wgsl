// The traversal stack in private memory: STACK_SIZE entries (node or child group, entry
// distance's bits), chosen per tree so its deepest walk fits (the host never picks this variant
// for a deeper tree).
const STACK_SIZE: u32 = {STACK_SIZE}u;
var<private> stack: array<vec2<u32>, STACK_SIZE>;

fn stack_init(invocation: u32) {}
fn stack_set(i: u32, e: vec2<u32>) { stack[i] = e; }
fn stack_get(i: u32) -> vec2<u32> { return stack[i]; }
