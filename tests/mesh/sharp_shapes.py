"""Closed forms of the sharp test shapes in tests/data/features (the cube,
the rotated cube, two boxes, a tilted cylinder cut by a slab, the clean
union of two spheres) and of the stool's arguments, computed here with
numpy, not by libblend; shared by test_mesh_features.py and
test_mesh_simplify.py."""
import json
import os

import numpy as np
from scipy.spatial import cKDTree

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "features")


def samples(V, F, k=6):
    P = V[F]
    bs = [(i / k, j / k, 1 - (i + j) / k) for i in range(k + 1) for j in range(k + 1 - i)]
    return np.concatenate([a * P[:, 0] + b * P[:, 1] + c * P[:, 2] for a, b, c in bs])


def scene(name):
    with open(os.path.join(DATA, name + ".json")) as f:
        return json.load(f)


def cell_size(sc, res):
    lo, hi = np.array(sc["bounds"]["min"]), np.array(sc["bounds"]["max"])
    return (hi - lo).max() / res


def box_distance(p, R, c, a):
    """|exact signed distance| to the box centre c, half sides a, axes the rows of R"""
    q = np.abs((p - c) @ R.T) - a
    return np.abs(np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(1), 0))


def rect_distance(p, d, x, lo, hi, _s=None):
    """distance to the rectangle {p[d] = x, other coordinates in [lo, hi]}
    (_s: the side its outward normal points to, unused here)"""
    q = p.copy()
    q[:, d] = x
    for t, i in enumerate([i for i in range(3) if i != d]):
        q[:, i] = np.clip(p[:, i], lo[t], hi[t])
    return np.linalg.norm(p - q, axis=1)


def union_faces(boxes):
    """the boundary of a union of two axis-aligned boxes as rectangles: each
    face of one box minus the other box's open cross-section"""
    rects = []
    for (c, a), (oc, oa) in ((boxes[0], boxes[1]), (boxes[1], boxes[0])):
        for d in range(3):
            o = [i for i in range(3) if i != d]
            for s in (-1, 1):
                x = c[d] + s * a[d]
                lo = [c[i] - a[i] for i in o]
                hi = [c[i] + a[i] for i in o]
                pieces = [(lo, hi)]
                if oc[d] - oa[d] < x < oc[d] + oa[d]:
                    slo = [max(lo[t], oc[i] - oa[i]) for t, i in enumerate(o)]
                    shi = [min(hi[t], oc[i] + oa[i]) for t, i in enumerate(o)]
                    if slo[0] < shi[0] and slo[1] < shi[1]:
                        pieces = []
                        if lo[0] < slo[0]:
                            pieces.append(([lo[0], lo[1]], [slo[0], hi[1]]))
                        if shi[0] < hi[0]:
                            pieces.append(([shi[0], lo[1]], [hi[0], hi[1]]))
                        if lo[1] < slo[1]:
                            pieces.append(([slo[0], lo[1]], [shi[0], slo[1]]))
                        if shi[1] < hi[1]:
                            pieces.append(([slo[0], shi[1]], [shi[0], hi[1]]))
                rects += [(d, x, l, u, s) for l, u in pieces]
    return rects


def slabs_of(node):
    """(R, centre, half sides) of a box written as max of three slabs"""
    R = np.array([np.array(s["normal"]) / np.linalg.norm(s["normal"]) for s in node["args"]])
    c = np.array(node["args"][0].get("point", [0, 0, 0]), float)
    a = np.array([s["half_width"] for s in node["args"]], float)
    return R, c, a


def box_normal(name):
    """the outward unit normal of the face of the cube, rotated cube or boxes
    nearest to each point"""
    root = scene(name)["root"]
    if root["type"] == "max":
        R, c, a = slabs_of(root)

        def normal(p):
            q = (p - c) @ R.T
            d = np.argmax(np.abs(q) - a, axis=1)
            return np.sign(q[np.arange(len(p)), d])[:, None] * R[d]
        return normal
    rects = union_faces(box_parts(root))

    def normal(p):
        k = np.argmin([rect_distance(p, *r) for r in rects], axis=0)
        out = np.zeros((len(p), 3))
        for i, (d, _x, _l, _u, s) in enumerate(rects):
            out[k == i, d] = s
        return out
    return normal


def box_parts(root):
    boxes = []
    for arg in root["args"]:
        R, _c, a = slabs_of(arg)
        assert np.allclose(R, np.eye(3))
        c = np.array([s.get("point", [0, 0, 0])[i] for i, s in enumerate(arg["args"])], float)
        boxes.append((c, a))
    return boxes


def box_like(name):
    """distance function and convex corners of the cube, rotated cube, boxes"""
    sc = scene(name)
    root = sc["root"]
    if root["type"] == "max":
        R, c, a = slabs_of(root)
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)],
                           float) * a @ R + c
        return (lambda p: box_distance(p, R, c, a)), corners
    boxes = box_parts(root)
    rects = union_faces(boxes)
    corners = []
    for (c, a), (oc, oa) in ((boxes[0], boxes[1]), (boxes[1], boxes[0])):
        for s in np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]):
            p = c + a * s
            if not np.all(np.abs(p - oc) <= oa):
                corners.append(p)
    return (lambda p: np.min([rect_distance(p, *r) for r in rects], axis=0)), np.array(corners)


def cylinder_slab():
    """(distance, normal, radius) of the tilted cylinder cut by a slab:
    distance(p) gives the distance to the surface and to the crease curves,
    normal(p) the outward normal of the piece nearest to p"""
    sc = scene("cylinder-slab")
    cyl, slab = sc["root"]["args"]
    ax = np.array(cyl["axis"], float)
    ax /= np.linalg.norm(ax)
    r = cyl["radius"]
    z0, hw = slab["point"][2], slab["half_width"]
    e1 = np.cross(ax, [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(ax, e1)

    def crease_point(t, zc):
        """the cylinder's point at angle t on the plane z = zc"""
        ring = r * (np.cos(t)[:, None] * e1 + np.sin(t)[:, None] * e2)
        return ring + ((zc - ring[:, 2]) / ax[2])[:, None] * ax


    def crease_distance(p):
        """distance to the two crease curves: the nearest of 4096 samples, then a
        ternary search on the angle around it (the distance is unimodal there)"""
        best = np.full(len(p), np.inf)
        coarse = np.linspace(0, 2 * np.pi, 4096, endpoint=False)
        step = coarse[1] - coarse[0]
        for zc in (z0 - hw, z0 + hw):
            t0 = coarse[cKDTree(crease_point(coarse, zc)).query(p)[1]]
            lo, hi = t0 - step, t0 + step
            for _ in range(60):
                m1, m2 = lo + (hi - lo) / 3, hi - (hi - lo) / 3
                d1 = np.linalg.norm(p - crease_point(m1, zc), axis=1)
                d2 = np.linalg.norm(p - crease_point(m2, zc), axis=1)
                closer = d1 < d2
                hi = np.where(closer, m2, hi)
                lo = np.where(closer, lo, m1)
            best = np.minimum(best, np.linalg.norm(p - crease_point(0.5 * (lo + hi), zc), axis=1))
        return best


    def cyl_slab_distance(p):
        dc = crease_distance(p)
        along = p @ ax
        radial = np.linalg.norm(p - along[:, None] * ax, axis=1)
        q = along[:, None] * ax + (p - along[:, None] * ax) / np.maximum(radial, 1e-300)[:, None] * r
        side = np.where(np.abs(q[:, 2] - z0) <= hw, np.abs(radial - r), dc)
        caps = []
        for zc in (z0 - hw, z0 + hw):
            pp = p.copy()
            pp[:, 2] = zc
            al = pp @ ax
            rad = np.linalg.norm(pp - al[:, None] * ax, axis=1)
            caps.append(np.where(rad <= r, np.abs(p[:, 2] - zc), dc))
        return np.minimum(side, np.minimum(*caps)), dc


    def cyl_slab_normal(p):
        """the outward normal of the piece (side or either cap) nearest to p"""
        along = p @ ax
        rv = p - along[:, None] * ax
        radial = np.linalg.norm(rv, axis=1)
        q = along[:, None] * ax + rv / radial[:, None] * r
        dside = np.where(np.abs(q[:, 2] - z0) <= hw, np.abs(radial - r), np.inf)
        dtop, dbot = np.abs(p[:, 2] - (z0 + hw)), np.abs(p[:, 2] - (z0 - hw))
        n = rv / radial[:, None]
        n[(dtop < dside) & (dtop <= dbot)] = [0, 0, 1]
        n[(dbot < dside) & (dbot < dtop)] = [0, 0, -1]
        return n


    return cyl_slab_distance, cyl_slab_normal, r


def union_spheres(name="clean-union-spheres"):
    """distance(p) of the union of two spheres (the clean union, or the
    local union outside its blending volume): the distance to the surface
    and to the crease circle"""
    sc = scene(name)
    (s1, s2) = sc["root"]["args"]
    c1, r1 = np.array(s1["center"], float), s1["radius"]
    c2, r2 = np.array(s2["center"], float), s2["radius"]
    dd = np.linalg.norm(c2 - c1)
    u = (c2 - c1) / dd
    aa = (dd * dd + r1 * r1 - r2 * r2) / (2 * dd)
    rho = np.sqrt(r1 * r1 - aa * aa)
    cc = c1 + aa * u

    def union_spheres_distance(p):
        w = p - cc
        wa = w @ u
        circ = np.sqrt(wa ** 2 + (np.linalg.norm(w - wa[:, None] * u, axis=1) - rho) ** 2)
        out = []
        for c, rr, oc, orr in ((c1, r1, c2, r2), (c2, r2, c1, r1)):
            dl = np.linalg.norm(p - c, axis=1)
            proj = c + (p - c) / np.maximum(dl, 1e-300)[:, None] * rr
            out.append(np.where(np.linalg.norm(proj - oc, axis=1) >= orr, np.abs(dl - rr), circ))
        return np.minimum(*out), circ


    return union_spheres_distance


def ellipsoid_distance(p, center, semi_axes):
    """unsigned distance from p to the ellipsoid's surface: the nearest
    point is a_i^2 q_i / (t + a_i^2) (q = |p - center|) for the root t >
    -min a_i^2 of sum (a_i q_i / (t + a_i^2))^2 = 1, decreasing in t;
    bisected 80 times (the bracket, a few units wide, to below 1e-20)"""
    q = np.abs(np.asarray(p, float) - center)
    a = np.asarray(semi_axes, float)
    lo = np.full(len(q), -a.min() ** 2)
    hi = np.full(len(q), a.max() * np.linalg.norm(q, axis=1) + 1.0)
    for _ in range(80):
        t = 0.5 * (lo + hi)
        above = np.sum((a * q / (t[:, None] + a * a)) ** 2, axis=1) > 1.0
        lo, hi = np.where(above, t, lo), np.where(above, hi, t)
    t = 0.5 * (lo + hi)
    return np.linalg.norm(q - a * a * q / (t[:, None] + a * a), axis=1)


def capsule_value(p, start, end, radius):
    """signed distance to a capsule (negative inside)"""
    s, e = np.asarray(start, float), np.asarray(end, float)
    v = e - s
    t = np.clip(((p - s) @ v) / (v @ v), 0.0, 1.0)
    return np.linalg.norm(p - (s + t[:, None] * v), axis=1) - radius


def stool(path):
    """(distance, lone) for hsu-bounded Fig. 7, the stool (a bounded union
    of an ellipsoid plate and four capsule legs): lone(p) says p is inside
    at most one bounding solid, where the bounded union is the plain union
    of the arguments (tests/figures checks that); near such points only one
    argument is near, so distance(p) is the distance to the nearest
    argument's surface"""
    with open(path) as f:
        root = json.load(f)["root"]

    def inside(node, p):
        if node["type"] == "ellipsoid":
            c, a = np.asarray(node["center"], float), np.asarray(node["semi_axes"], float)
            return np.sum(((p - c) / a) ** 2, axis=1) <= 1.0
        return capsule_value(p, node["start"], node["end"], node["radius"]) <= 0.0

    def lone(p):
        return np.sum([inside(b, p) for b in root["bounds"]], axis=0) <= 1

    def distance(p):
        return np.min([ellipsoid_distance(p, np.asarray(n["center"], float), n["semi_axes"])
                       if n["type"] == "ellipsoid" else
                       np.abs(capsule_value(p, n["start"], n["end"], n["radius"]))
                       for n in root["args"]], axis=0)

    return distance, lone
