// The traversal stack in global memory, for a tree deeper than a private stack holds (an imported
// one may be of any depth): each invocation of the dispatch owns P.stack_stride entries of `gstack`,
// as many as the tree's deepest walk needs; the host runs the rays in batches small enough that
// the buffer fits the adapter's limit.
const STACK_SIZE: u32 = 0xffffffffu;
@group(0) @binding(4) var<storage, read_write> gstack: array<vec2<u32>>;
var<private> stack_base: u32;

fn stack_init(invocation: u32) { stack_base = invocation * P.stack_stride; }
fn stack_set(i: u32, e: vec2<u32>) { gstack[stack_base + i] = e; }
fn stack_get(i: u32) -> vec2<u32> { return gstack[stack_base + i]; }
