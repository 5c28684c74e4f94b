"""Independent readers and checks for libblend's mesh files (numpy only).

read(path) -> (V, N, F): float64 positions, normals (or None), int64 triangles,
for binary PLY, OBJ, binary STL (vertices merged by exact position) and GLB.
check(V, F) -> dict with closed, oriented, manifold, euler, volume, ...
"""
import json
import struct

import numpy as np


def read_ply(path):
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    assert header[0] == "ply" and header[1] == "format binary_little_endian 1.0", header[:2]
    nv = nf = None
    vprops = []
    cur = None
    for line in header:
        w = line.split()
        if w[0] == "element":
            cur = w[1]
            if cur == "vertex":
                nv = int(w[2])
            elif cur == "face":
                nf = int(w[2])
        elif w[0] == "property" and cur == "vertex":
            assert w[1] == "float", line
            vprops.append(w[2])
        elif w[0] == "property" and cur == "face":
            assert w[1:4] == ["list", "uchar", "uint"], line
    verts = np.frombuffer(data, dtype="<f4", count=nv * len(vprops), offset=end).reshape(nv, len(vprops))
    off = end + 4 * nv * len(vprops)
    rec = np.dtype([("n", "u1"), ("i", "<u4", (3,))])
    faces = np.frombuffer(data, dtype=rec, count=nf, offset=off)
    assert np.all(faces["n"] == 3)
    assert off + nf * 13 == len(data), "trailing bytes in PLY"
    V = verts[:, [vprops.index(c) for c in "xyz"]].astype(np.float64)
    N = verts[:, [vprops.index(c) for c in ("nx", "ny", "nz")]].astype(np.float64) if "nx" in vprops else None
    return V, N, faces["i"].astype(np.int64)


def read_obj(path):
    V, N, F, _FN = read_obj_corners(path)
    return V, N, F


def read_obj_corners(path):
    """An OBJ's positions, normals (or None), triangles and each corner's
    normal index (the n of f v//n; -1 where a corner names none), all
    0-based: (V, N, F, FN)."""
    V, N, F, FN = [], [], [], []
    with open(path) as f:
        for line in f:
            w = line.split()
            if not w or w[0].startswith("#"):
                continue
            if w[0] == "v":
                V.append([float(x) for x in w[1:4]])
            elif w[0] == "vn":
                N.append([float(x) for x in w[1:4]])
            elif w[0] == "f":
                parts = [x.split("/") for x in w[1:]]
                assert len(parts) == 3
                F.append([int(q[0]) - 1 for q in parts])
                FN.append([int(q[2]) - 1 if len(q) == 3 and q[2] else -1 for q in parts])
    return (np.array(V), (np.array(N) if N else None), np.array(F, dtype=np.int64),
            np.array(FN, dtype=np.int64))


def read_stl(path):
    with open(path, "rb") as f:
        data = f.read()
    (n,) = struct.unpack_from("<I", data, 80)
    assert len(data) == 84 + 50 * n, "STL size does not match its triangle count"
    rec = np.dtype([("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    tris = np.frombuffer(data, dtype=rec, count=n, offset=84)
    P = tris["v"].reshape(-1, 3)
    V, inv = np.unique(P, axis=0, return_inverse=True)
    return V.astype(np.float64), None, inv.reshape(-1, 3).astype(np.int64)


def read_glb(path):
    with open(path, "rb") as f:
        data = f.read()
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    assert magic == b"glTF" and version == 2 and length == len(data)
    jlen, jtype = struct.unpack_from("<I4s", data, 12)
    assert jtype == b"JSON"
    doc = json.loads(data[20:20 + jlen])
    if "meshes" not in doc:  # a scene without nodes: the empty mesh
        assert len(data) == 20 + jlen and "buffers" not in doc
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    blen, btype = struct.unpack_from("<I4s", data, 20 + jlen)
    assert btype == b"BIN\0"
    bin_ = data[28 + jlen:28 + jlen + blen]

    def acc(i, dtype, comps):
        a = doc["accessors"][i]
        v = doc["bufferViews"][a["bufferView"]]
        return np.frombuffer(bin_, dtype=dtype, count=a["count"] * comps,
                             offset=v["byteOffset"] + a.get("byteOffset", 0)).reshape(a["count"], comps) if comps > 1 else \
            np.frombuffer(bin_, dtype=dtype, count=a["count"], offset=v["byteOffset"] + a.get("byteOffset", 0))

    p = doc["meshes"][0]["primitives"][0]
    V = acc(p["attributes"]["POSITION"], "<f4", 3).astype(np.float64)
    N = acc(p["attributes"]["NORMAL"], "<f4", 3).astype(np.float64)
    F = acc(p["indices"], "<u4", 1).astype(np.int64).reshape(-1, 3)
    return V, N, F


def read(path):
    ext = path.rsplit(".", 1)[-1].lower()
    return {"ply": read_ply, "obj": read_obj, "stl": read_stl, "glb": read_glb}[ext](path)


def check(V, F):
    """Closedness, orientation, manifoldness (edge use and vertex links),
    Euler characteristic, components and signed volume."""
    out = {"vertices": len(V), "triangles": len(F)}
    if len(F) == 0:
        out.update(closed=True, oriented=True, manifold=True, euler=0, volume=0.0, components=0)
        return out
    nv = len(V)
    # directed half-edges: in a closed, consistently oriented mesh each
    # directed edge appears once and its reverse once
    a = F.reshape(-1)
    b = F[:, [1, 2, 0]].reshape(-1)
    directed = a * nv + b
    uniq, counts = np.unique(directed, return_counts=True)
    out["oriented"] = bool(np.all(counts == 1))
    rev = b * nv + a
    out["closed"] = bool(np.all(np.isin(rev, uniq)))
    und = np.minimum(a, b) * nv + np.maximum(a, b)
    ue, uc = np.unique(und, return_counts=True)
    out["edge_use_ok"] = bool(np.all(uc == 2))
    out["degenerate_index"] = int(np.sum((F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 0] == F[:, 2])))
    used = np.unique(F)
    E = len(ue)
    out["euler"] = int(len(used) - E + len(F))
    out["unused_vertices"] = int(nv - len(used))
    # vertex links: around each vertex the opposite edges form one cycle
    order = np.argsort(np.concatenate([F[:, 0], F[:, 1], F[:, 2]]), kind="stable")
    corner_v = np.concatenate([F[:, 0], F[:, 1], F[:, 2]])[order]
    nxt = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])[order]
    prv = np.concatenate([F[:, 2], F[:, 0], F[:, 1]])[order]
    starts = np.searchsorted(corner_v, used)
    ends = np.searchsorted(corner_v, used, side="right")
    bad_links = 0
    for s, e in zip(starts, ends):
        link = dict(zip(nxt[s:e].tolist(), prv[s:e].tolist()))
        if len(link) != e - s:
            bad_links += 1
            continue
        start = nxt[s]
        cur, steps = start, 0
        while True:
            cur = link.get(cur)
            steps += 1
            if cur is None or cur == start or steps > e - s:
                break
        if cur != start or steps != e - s:
            bad_links += 1
    out["bad_vertex_links"] = bad_links
    out["manifold"] = out["edge_use_ok"] and bad_links == 0 and out["degenerate_index"] == 0
    # components (union-find over edges)
    parent = np.arange(nv)

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x
    for u, w in zip(a.tolist(), b.tolist()):
        ru, rw = find(u), find(w)
        if ru != rw:
            parent[ru] = rw
    out["components"] = len({find(int(v)) for v in used})
    P = V[F]
    out["volume"] = float(np.sum(np.einsum("ij,ij->i", P[:, 0], np.cross(P[:, 1], P[:, 2]))) / 6.0)
    return out
