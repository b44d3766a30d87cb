"""Writing a BVH in bvhscope's JSON form (`bvhscope-bvh` version 1) from Python.

`nodes` are dicts: interior {"min", "max", "children": [a, b], "axis"} or leaf {"min", "max",
"first", "count"}; `primitives` the triangle numbers of the mesh file the leaves index into
(faces in file order, polygons fanned (v0, vi, vi+1), zero-area triangles counted).

    python3 dump_bvh.py > tree.json && bvhscope check row.obj --bvh tree.json
"""
import json
import sys


def write_bvhscope_dump(out, nodes, primitives, mesh=None):
    dump = {"format": "bvhscope-bvh", "version": 1, "primitives": list(primitives), "nodes": nodes}
    if mesh:
        dump["mesh"] = mesh
    json.dump(dump, out)


if __name__ == "__main__":
    # The same tiny tree as dump_bvh.cpp, over the four triangles of row.obj.
    nodes = [
        {"min": [0, 0, 0], "max": [4, 1, 0], "children": [1, 2], "axis": 0},
        {"min": [0, 0, 0], "max": [2, 1, 0], "first": 0, "count": 2},
        {"min": [2, 0, 0], "max": [4, 1, 0], "first": 2, "count": 2},
    ]
    write_bvhscope_dump(sys.stdout, nodes, [1, 0, 3, 2], "row.obj")
