// Writing a BVH in bvhscope's text form (`bvhscope-bvh 1`), from a renderer whose BVH is the
// lab's: an array of BVHNode {left, right, box, firstShapeOffset, nShape, splitAxis} and the
// `orderedShapes` the leaves index into. Copy `writeBvhscopeDump` into your renderer; `main` below
// builds a tiny tree by hand so `tests/cli.rs` can compile, run and check it.
//
//   g++ -std=c++17 -O1 dump_bvh.cpp -o dump_bvh && ./dump_bvh > tree.txt
//   bvhscope check row.obj --bvh tree.txt
#include <cstdio>
#include <vector>

struct Point3f { float x, y, z; };
struct AABB { Point3f pMin, pMax; };

// The lab's node: an interior node has both children (indices into the node array); a leaf has
// nShape > 0 shapes starting at orderedShapes[firstShapeOffset].
struct BVHNode {
    int left = -1, right = -1;
    AABB box;
    int firstShapeOffset = 0, nShape = 0;
    int splitAxis = 0;
};

// `orderedShapes[i]` is the triangle's number in the mesh file: its faces in order, a polygon
// fanned into triangles (v0, vi, vi+1), zero-area ones counted. (If your renderer keeps shape
// pointers, write each shape's triangle number.)
void writeBvhscopeDump(std::FILE* out, const std::vector<BVHNode>& nodes, const std::vector<int>& orderedShapes,
                       const char* meshName) {
    std::fprintf(out, "bvhscope-bvh 1\n");
    if (meshName) std::fprintf(out, "mesh %s\n", meshName);
    for (size_t i = 0; i < orderedShapes.size(); ++i) {
        std::fprintf(out, i % 32 == 0 ? (i ? "\nprimitives %d" : "primitives %d") : " %d", orderedShapes[i]);
    }
    std::fprintf(out, "\n");
    for (const BVHNode& n : nodes) {
        // %.9g keeps every bit of a float, so the boxes read back exactly.
        std::fprintf(out, "node %.9g %.9g %.9g %.9g %.9g %.9g", n.box.pMin.x, n.box.pMin.y, n.box.pMin.z,
                     n.box.pMax.x, n.box.pMax.y, n.box.pMax.z);
        if (n.nShape > 0) {
            std::fprintf(out, " leaf %d %d\n", n.firstShapeOffset, n.nShape);
        } else {
            std::fprintf(out, " children %d %d axis %d\n", n.left, n.right, n.splitAxis);
        }
    }
}

int main() {
    // Four triangles in a row along x (row.obj in tests/cli.rs): triangle k spans x k..k+1, y 0..1.
    std::vector<int> orderedShapes = {1, 0, 3, 2};
    std::vector<BVHNode> nodes(3);
    nodes[0].box = {{0, 0, 0}, {4, 1, 0}};
    nodes[0].left = 1;
    nodes[0].right = 2;
    nodes[1].box = {{0, 0, 0}, {2, 1, 0}};
    nodes[1].firstShapeOffset = 0;
    nodes[1].nShape = 2;
    nodes[2].box = {{2, 0, 0}, {4, 1, 0}};
    nodes[2].firstShapeOffset = 2;
    nodes[2].nShape = 2;
    writeBvhscopeDump(stdout, nodes, orderedShapes, "row.obj");
    return 0;
}
