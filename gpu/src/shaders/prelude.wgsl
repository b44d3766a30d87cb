// What every module of this crate that reads triangles shares, put before its own source when
// the module is made (`kernel::module`): a triangle's three vertices, 36 bytes, in the order of
// core's Bvh::tris (leaf order for the walks, the mesh's order for the builders).

struct Tri { v: array<f32, 9> }
