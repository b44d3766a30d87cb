"""Rewrite a bvhscope-bvh text dump the way a common student bug does: each leaf's box is the box of its
triangles' centroids (not their corners), and each interior box the union of its children's. The README's
walkthrough of `bvhscope check` uses it to make a broken dump from an exported one.
Usage: python3 centroid_boxes.py MESH.obj IN.txt > OUT.txt"""
import sys

def triangles(path):
    v, tris = [], []
    for line in open(path):
        w = line.split()
        if not w:
            continue
        if w[0] == "v":
            v.append(tuple(float(x) for x in w[1:4]))
        elif w[0] == "f":
            idx = [int(x.split("/")[0]) for x in w[1:]]
            idx = [i - 1 if i > 0 else len(v) + i for i in idx]
            for k in range(1, len(idx) - 1):
                tris.append((v[idx[0]], v[idx[k]], v[idx[k + 1]]))
    return tris

tris = triangles(sys.argv[1])
lines = open(sys.argv[2]).read().split("\n")
prims, nodes, head = [], [], []
for l in lines:
    w = l.split()
    if w and w[0] == "primitives":
        prims += [int(x) for x in w[1:]]
    if w and w[0] == "node":
        nodes.append(w)
    elif l.strip():
        head.append(l)
boxes = [None] * len(nodes)

def box(i):
    w = nodes[i]
    if boxes[i] is None:
        if w[7] == "leaf":
            f, c = int(w[8]), int(w[9])
            cs = [tuple(sum(p[a] for p in tris[t]) / 3 for a in range(3)) for t in prims[f:f + c]]
        else:
            rest = w[8:]
            kids = [int(x) for x in (rest[: rest.index("axis")] if "axis" in rest else rest)]
            cs = [p for k in kids for p in box(k)]
        boxes[i] = (tuple(min(p[a] for p in cs) for a in range(3)), tuple(max(p[a] for p in cs) for a in range(3)))
    return boxes[i]

sys.setrecursionlimit(100000)
box(0)
print("\n".join(head))
for i, w in enumerate(nodes):
    lo, hi = boxes[i] if boxes[i] else (tuple(map(float, w[1:4])), tuple(map(float, w[4:7])))
    print("node %.9g %.9g %.9g %.9g %.9g %.9g %s" % (*lo, *hi, " ".join(w[7:])))
