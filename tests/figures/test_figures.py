#!/usr/bin/python3
"""Each gallery figure's visible claim, measured on meshes and fields of the
shipped scenes (not on pixels):

    /usr/bin/python3 test_figures.py BINDING_DIR SOURCE_DIR

1. hsu2006 Fig. 7 (BT_3 cube inside BT_2 with a super-ellipsoid, m2 swept):
   away from the super-ellipsoid the cube's blended surface does not move
   with m2 (Hausdorff distance between the meshes there below 1e-3 of the
   scene size), while the subsequent blend's surface does move.
2. hsu-nonuniform Fig. 6 (soft B_S2(B_A3(f1, f2, f3), f4), m1 swept): the
   0.5-set away from f4 does not move with m1; and on the surface, where f1
   blends with f4, f1 spans the field range (1 - (1 - r_a)^m1) / 2 below 0.5
   (the paper's claim), for every m1 of the sweep and for f3 (m3 = 1).
3. hsu-bounded Fig. 7 (the stool, a bounded union): an argument blends
   only inside its own bounding solid, so wherever no two bounding solids
   meet the solid is the plain union's (min f_i), point for point, and the
   meshes coincide there; where they meet, the fillets move the surface.
4. hsu2006 Fig. 9 (the wheel's crossing spokes, bulge elimination): the
   bulge above the crossing, measured along the z axis, is reduced by a
   stated factor against the same blend without bulge elimination.
5. hsu-nonuniform Fig. 5 (the level sets B_A3 = h of soft slabs, m1 = 0.6,
   m2 = 2.8): as h falls from 0.5 the f2 faces move out farther than the
   f1 faces, and at each face's centre f_i = 0.5 (h / 0.5)^m_i (the
   primitives become 0.5 (f_i / 0.5)^(1/m_i)).
6. hsu-bounded Fig. 8 (a column on a plate, bounded unions): the fillet
   lies inside the column's bounding solid, and its footprint on the plate
   takes that solid's cross-section: round, square or elliptical.
7. hsu2006 Fig. 8 (a slot cut from a box): lowering m6 and m12 to 0.3
   removes the slot floor's blend with the top face (the floor's centre
   comes back to its plane) and changes neither box.
8. bernhardt2010 Figs. 6 and 8 (local union): the smaller sphere's flank
   is the sharp union's with the local union and swollen with the soft sum;
   a drop above the water is exactly a sphere until it touches, and joins
   the water with a neck once it does.

The distance of a mesh vertex v to the other surface is |f(v) - level| /
|grad f(v)| (first order; the fields are smooth there and the distances
small); a Hausdorff distance is the larger of the two directions' maxima.
"""
import copy
import json
import math
import os
import sys

import numpy as np

BINDING, SRC = sys.argv[1:3]
sys.path.insert(0, BINDING)
import binding  # noqa: E402

lib = binding.load()
checks = 0


def check(cond, what):
    global checks
    checks += 1
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        raise SystemExit("test_figures: " + what)


def scene(name):
    return json.load(open(os.path.join(SRC, "scenes", name)))


def with_root(doc, root):
    out = {k: v for k, v in doc.items() if k not in ("root", "render", "defs")}
    out["root"] = root
    return out


class Field:
    def __init__(self, doc):
        self.level = 0.5 if doc["convention"] == "soft" else 0.0
        self.sc = lib.parse_scene(json.dumps(doc), doc.get("title", "figure"))
        self.ev = self.sc.compile()
        self.doc = doc

    def values(self, P):
        return self.ev.eval(np.asarray(P), gradient=False)[0]

    def distance(self, P):
        v, g = self.ev.eval(np.asarray(P))
        return np.abs(v - self.level) / np.maximum(np.linalg.norm(g, axis=1), 1e-300)

    def mesh(self, cells):
        """the vertices of a mesh of the field; where the surface leaves the
        region the mesher closes it along the region's faces, and those
        vertices (not on the surface) are left out"""
        b = self.doc["bounds"]
        P = self.ev.mesh(b["min"], b["max"], resolution=cells).positions
        eps = 1e-9 * size(self.doc)
        keep = np.all((P > np.asarray(b["min"]) + eps) & (P < np.asarray(b["max"]) - eps), axis=1)
        return P[keep]


def size(doc):
    b = doc["bounds"]
    return float(np.linalg.norm(np.subtract(b["max"], b["min"])))


def hausdorff(fa, pa, fb, pb, mask_a, mask_b):
    """the two-sided distance between surfaces a and b over the vertices
    the masks keep"""
    da = fb.distance(pa[mask_a]).max() if mask_a.any() else 0.0
    db = fa.distance(pb[mask_b]).max() if mask_b.any() else 0.0
    return max(da, db)


CELLS = 128

# ---------------------------------------------------------------- 1. hsu2006 Fig. 7
docs = [scene("hsu2006-fig7-m%s.json" % m) for m in ("0.3", "0.6", "0.9", "1.2")]
S = size(docs[0])
fields = [Field(d) for d in docs]
sq = Field(with_root(docs[0], docs[0]["root"]["args"][1]))  # the super-ellipsoid alone
r_outer = docs[0]["root"]["r"]
meshes = [f.mesh(CELLS) for f in fields]
far = [sq.values(p) > r_outer + 0.15 for p in meshes]    # beyond the later blend's reach
near = [sq.values(p) < 0.5 * r_outer for p in meshes]    # inside it
for i in range(1, 4):
    h_far = hausdorff(fields[0], meshes[0], fields[i], meshes[i], far[0], far[i])
    h_near = hausdorff(fields[0], meshes[0], fields[i], meshes[i], near[0], near[i])
    print("Fig. 7, m2 = 0.3 against %s: Hausdorff %.3g away from the super-ellipsoid "
          "(%d / %d vertices), %.3g in the subsequent blend (scene size %.3g)"
          % (docs[i]["title"].split(", ")[1], h_far, far[0].sum(), far[i].sum(), h_near, S))
    check(far[0].sum() > 1000 and near[0].sum() > 200, "Fig. 7: both regions hold vertices")
    check(h_far < 1e-3 * S, "Fig. 7: the first blend's surface does not move with m2 (%.3g < %.3g)"
          % (h_far, 1e-3 * S))
    check(h_near > 0.01 * S * i / 3, "Fig. 7: the subsequent blend moves with m2 (%.3g > %.3g)"
          % (h_near, 0.01 * S * i / 3))

# ---------------------------------------------------------------- 2. hsu-nonuniform Fig. 6
ms = ("0.3", "0.65", "1", "1.5")
docs = [scene("hsu-nonuniform-fig6-m%s.json" % m) for m in ms]
S = size(docs[0])
fields = [Field(d) for d in docs]
meshes = [f.mesh(CELLS) for f in fields]
root0 = docs[0]["root"]
f4 = Field(with_root(docs[0], root0["args"][1]))
r_a = root0["r"]
far = [f4.values(p) < 0.02 for p in meshes]
near = [f4.values(p) > 0.3 for p in meshes]
for i in range(1, 4):
    h_far = hausdorff(fields[0], meshes[0], fields[i], meshes[i], far[0], far[i])
    h_near = hausdorff(fields[0], meshes[0], fields[i], meshes[i], near[0], near[i])
    print("Fig. 6, m1 = 0.3 against m1 = %s: Hausdorff %.3g away from f4 (%d / %d vertices), "
          "%.3g in the outer blend" % (ms[i], h_far, far[0].sum(), far[i].sum(), h_near))
    check(h_far < 1e-3 * S, "Fig. 6: the 0.5-set does not move with m1 (%.3g < %.3g)"
          % (h_far, 1e-3 * S))
    check(h_near > 2e-3 * S, "Fig. 6: the outer blend moves with m1 (%.3g)" % h_near)
# the range: at surface points where the outer blend acts and the inner
# intersection is its argument i alone (not blending there), f_i reaches
# down to 0.5 (1 - r_a)^m_i
RANGE_CELLS = 256
for d, f, m in zip(docs, fields, ms):
    inner_doc = d["root"]["args"][0]
    inner = Field(with_root(d, inner_doc))
    P = f.mesh(RANGE_CELLS)
    cell = max(np.subtract(d["bounds"]["max"], d["bounds"]["min"])) / RANGE_CELLS
    vi, v4 = inner.values(P), f4.values(P)
    # the outer blend raises the field above both arguments (vertices are on
    # the surface to 1e-6 of a cell: 1e-5 is far above that error)
    blending = np.maximum(vi, v4) < 0.5 - 1e-5
    for arg in (0, 2):
        mi = inner_doc["m"][arg]
        fi = Field(with_root(d, inner_doc["args"][arg]))
        vf, gf = fi.ev.eval(P)
        alone = np.abs(vi - 0.5 * (np.maximum(vf, 0) / 0.5) ** (1.0 / mi)) < 1e-9
        sel = blending & alone & (vf > 0)
        want = 0.5 * (1 - r_a) ** mi
        got = float(vf[sel].min()) if sel.any() else float("nan")
        tol = 1.5 * cell * float(np.linalg.norm(gf[sel], axis=1).max()) if sel.any() else 0
        print("Fig. 6, m1 = %s: f%d (m = %g) blends with f4 down to %.4f over %d vertices; "
              "the claim 0.5 (1 - r_a)^m = %.4f, range %.4f (tolerance %.4f: 1.5 cells)"
              % (m, arg + 1, mi, got, sel.sum(), want, 0.5 - want, tol))
        check(sel.sum() > 50 and abs(got - want) < tol,
              "Fig. 6: f%d's blend range with f4 is (1 - (1 - r_a)^m)/2 at m1 = %s" % (arg + 1, m))

# ---------------------------------------------------------------- 3. hsu-bounded Fig. 7
d = scene("hsu-bounded-fig7-stool.json")
S = size(d)
root = d["root"]
bounded = Field(d)
plain = Field(with_root(d, {"type": "min", "args": root["args"]}))
bounds = [Field(with_root(d, b)) for b in root["bounds"]]
rng = np.random.default_rng(7)
lo, hi = np.array(d["bounds"]["min"]), np.array(d["bounds"]["max"])
X = lo + (hi - lo) * rng.random((200000, 3))
def lone(P):
    """points inside at most one bounding solid: at the surface an argument
    blends only inside its own bounding solid, and a blend needs two"""
    return np.sum([b.values(P) <= 0 for b in bounds], axis=0) <= 1


outside = lone(X)
vb, vp = bounded.values(X[outside]), plain.values(X[outside])
differ = int(((vb < 0) != (vp < 0)).sum())
print("Fig. 7 (stool): %d random points inside at most one bounding solid, %d of them in the "
      "plain union, %d differ in the bounded one" % (outside.sum(), (vp < 0).sum(), differ))
check(outside.sum() > 10000 and (vp < 0).sum() > 1000 and differ == 0,
      "stool: where no two bounding solids meet, the bounded union is the plain union (%d differ)"
      % differ)
pb, pp = bounded.mesh(CELLS), plain.mesh(CELLS)
ob, op = lone(pb), lone(pp)
h_out = hausdorff(bounded, pb, plain, pp, ob, op)
h_in = bounded.distance(pp[~op]).max()
print("stool: Hausdorff %.3g where no two bounding solids meet (%d / %d vertices); the plain "
      "union's vertices where they do lie up to %.3g from the bounded surface"
      % (h_out, ob.sum(), op.sum(), h_in))
check(ob.sum() > 1000 and h_out < 1e-3 * S, "stool: the meshes coincide outside the bounding "
      "solids' overlaps (%.3g < %.3g)" % (h_out, 1e-3 * S))
check(h_in > 0.01 * S, "stool: inside them the bounded blend adds fillets (%.3g)" % h_in)

# ---------------------------------------------------------------- 4. hsu2006 Fig. 9
d = scene("hsu2006-fig9-m1.json")
spokes = d["root"]["args"][0]["args"][0]
assert "bulge" in spokes
without = copy.deepcopy(spokes)
del without["bulge"]
radius = spokes["args"][0]["radius"]


def top(node):
    """the surface's height above the crossing, along +z (bisection)"""
    f = Field(with_root(d, node))
    a, b = 0.0, 1.0
    for _ in range(60):
        c = 0.5 * (a + b)
        if f.values([[0.0, 0.0, c]])[0] < 0:
            a = c
        else:
            b = c
    return 0.5 * (a + b)


bulge_on, bulge_off = top(spokes) - radius, top(without) - radius
FACTOR = 100
print("Fig. 9: the bulge above the crossing is %.3g with bulge elimination and %.3g without "
      "(%.0fx)" % (bulge_on, bulge_off, bulge_off / max(bulge_on, 1e-300)))
check(bulge_off > 0.05 * radius, "Fig. 9: the plain blend bulges (%.3g, over 5 %% of the spokes' radius)" % bulge_off)
check(abs(bulge_on) * FACTOR < bulge_off, "Fig. 9: bulge elimination reduces it %dx or more"
      % FACTOR)

# ---------------------------------------------------------------- 5. hsu-nonuniform Fig. 5


def extent(f, direction, lo=0.0, hi=2.4):
    """where the surface crosses the ray from the origin (bisection)"""
    D = np.asarray(direction, dtype=float)
    inside = f.values([D * lo])[0] > f.level
    for _ in range(60):
        c = 0.5 * (lo + hi)
        if (f.values([D * c])[0] > f.level) == inside:
            lo = c
        else:
            hi = c
    return 0.5 * (lo + hi)


hs = ("0.5", "0.45", "0.4", "0.35", "0.3")
docs = [scene("hsu-nonuniform-fig5-h%s.json" % h) for h in hs]
cube = docs[0]["root"]["args"][0]
slabs = [Field(with_root(docs[0], a)) for a in cube["args"]]
ext = []
for d, h in zip(docs, hs):
    f = Field(d)
    ex, ey = extent(f, [1, 0, 0]), extent(f, [0, 1, 0])
    ext.append((ex, ey))
    for axis, e in ((0, ex), (1, ey)):
        P = np.zeros((1, 3))
        P[0, axis] = e
        got, want = slabs[axis].values(P)[0], 0.5 * (float(h) / 0.5) ** cube["m"][axis]
        print("Fig. 5, h = %s: the f%d face at %.4f, f%d = %.6f there, 0.5 (h/0.5)^m = %.6f"
              % (h, axis + 1, e, axis + 1, got, want))
        check(abs(got - want) < 1e-6, "Fig. 5: at the f%d face, f%d = 0.5 (h/0.5)^m%d (h = %s)"
              % (axis + 1, axis + 1, axis + 1, h))
for i in range(1, len(hs)):
    dx, dy = ext[i][0] - ext[0][0], ext[i][1] - ext[0][1]
    print("Fig. 5, h = %s: the f1 faces moved out %.4f, the f2 faces %.4f" % (hs[i], dx, dy))
    check(dx > 0 and dy > 1.5 * dx, "Fig. 5: f2 (m = 2.8) dilates farther than f1 (m = 0.6) at "
          "h = %s" % hs[i])

# ---------------------------------------------------------------- 6. hsu-bounded Fig. 8
# the bounding solids' cross-sections at the plate's top (z = 0.15): the
# ellipsoid's (centre z 0.5, semi-axis 1 in z) is scaled by sqrt(1 - 0.35^2)
k = math.sqrt(1 - 0.35 ** 2)
want_extent = {"round": (0.6, 0.6, 0.6), "square": (0.6, 0.6, 0.6 * math.sqrt(2)),
               "ellipse": (0.95 * k, 0.4 * k, None)}
for shape, (wx, wy, wd) in want_extent.items():
    d = scene("hsu-bounded-fig8-%s.json" % shape)
    root = d["root"]
    f = Field(d)
    sharp = Field(with_root(d, {"type": "min", "args": root["args"]}))
    cb = Field(with_root(d, root["bounds"][1]))
    P = f.mesh(CELLS)
    cell = max(np.subtract(d["bounds"]["max"], d["bounds"]["min"])) / CELLS
    active = sharp.distance(P) > 1e-6
    col = Field(with_root(d, root["args"][1]))
    X = np.array(d["bounds"]["min"]) + np.subtract(d["bounds"]["max"], d["bounds"]["min"]) * \
        np.random.default_rng(3).random((100000, 3))
    solid = col.values(X) <= 0
    check(solid.sum() > 1000 and (cb.values(X[solid]) <= 0).all(),
          "Fig. 8 (%s): the bounding solid contains the column" % shape)
    inside = cb.values(P[active]) <= 1e-9
    foot = P[active & (P[:, 2] < 0.15 + 0.5 * cell)]
    r = np.hypot(foot[:, 0], foot[:, 1])
    along_x = r[np.abs(foot[:, 1]) < cell].max()
    along_y = r[np.abs(foot[:, 0]) < cell].max()
    diag = r[np.abs(np.abs(foot[:, 0]) - np.abs(foot[:, 1])) < cell].max()
    print("Fig. 8, %s bound: %d vertices in the fillet, %d outside the column's bounding solid; "
          "its footprint on the plate reaches %.3f along x, %.3f along y, %.3f diagonally"
          % (shape, active.sum(), (~inside).sum(), along_x, along_y, diag))
    check(active.sum() > 500 and inside.all(), "Fig. 8 (%s): the fillet lies inside the column's "
          "bounding solid" % shape)
    tol = 2.5 * cell
    check(abs(along_x - wx) < tol and abs(along_y - wy) < tol and
          (wd is None or abs(diag - wd) < tol),
          "Fig. 8 (%s): the footprint is the bounding solid's cross-section (%s, within %.3f)"
          % (shape, (wx, wy, wd), tol))

# ---------------------------------------------------------------- 7. hsu2006 Fig. 8
plain_doc, low_doc = scene("hsu2006-fig8-plain.json"), scene("hsu2006-fig8-lowered-m.json")
S = size(plain_doc)
for j, name in ((0, "b1 (the box)"), (1, "b2 (the slot)")):
    fa = Field(with_root(plain_doc, plain_doc["root"]["args"][j]))
    fb = Field(with_root(low_doc, low_doc["root"]["args"][j]))
    pa, pb = fa.mesh(CELLS), fb.mesh(CELLS)
    h = hausdorff(fa, pa, fb, pb, np.ones(len(pa), bool), np.ones(len(pb), bool))
    print("Fig. 8 (hsu2006): %s with m = 1 and m = 0.3: Hausdorff %.3g" % (name, h))
    check(h < 1e-3 * S, "hsu2006 Fig. 8: lowering m leaves %s as it was" % name)


def floor_height(doc):
    """the surface crossing on the vertical through the slot's centre, from
    inside the slot (above the floor) down into the box"""
    f = Field(doc)
    hi, lo = 0.95, 0.2  # above: in the slot (outside), below: in the box
    for _ in range(60):
        c = 0.5 * (lo + hi)
        if f.values([[0.0, 0.0, c]])[0] > 0:
            hi = c
        else:
            lo = c
    return 0.5 * (lo + hi)


z_plain, z_low = floor_height(plain_doc), floor_height(low_doc)
print("Fig. 8 (hsu2006): the slot floor's centre at z = %.6f with m = 1, %.6f with m = 0.3 "
      "(its plane: 0.65)" % (z_plain, z_low))
check(abs(z_low - 0.65) < 1e-6, "hsu2006 Fig. 8: with m = 0.3 the slot floor is flat")
check(abs(z_plain - 0.65) > 0.01, "hsu2006 Fig. 8: with m = 1 it blends with the top face "
      "(%.4f off its plane)" % abs(z_plain - 0.65))

# ---------------------------------------------------------------- 8. bernhardt2010
local, ssum = scene("bernhardt-compare-local.json"), scene("bernhardt-compare-sum.json")
sharp = with_root(local, {"type": "max", "args": local["root"]["args"]})
small = local["root"]["args"][1]["center"]


def flank(doc):
    """the surface along +y from the small sphere's centre: at right angles
    to the line between the centres, away from the intersection circle"""
    f = Field(doc)
    lo, hi = 0.0, 1.5
    for _ in range(60):
        c = 0.5 * (lo + hi)
        if f.values([[small[0], small[1] + c, small[2]]])[0] > 0.5:
            lo = c
        else:
            hi = c
    return 0.5 * (lo + hi)


y_sharp, y_local, y_sum = flank(sharp), flank(local), flank(ssum)
print("Fig. 6 (bernhardt): the small sphere's flank at %.6f from its centre (sharp union), %.6f "
      "(local union), %.6f (soft sum)" % (y_sharp, y_local, y_sum))
check(abs(y_local - y_sharp) < 1e-9, "bernhardt Fig. 6: the local union leaves the flank "
      "untouched")
check(y_sum - y_sharp > 0.03, "bernhardt Fig. 6: the soft sum swells it (%.3f)" % (y_sum - y_sharp))
fl, fs = Field(local), Field(sharp)
pl, ps = fl.mesh(CELLS), fs.mesh(CELLS)
moved = fs.distance(pl).max()
print("Fig. 6 (bernhardt): the local union's surface lies up to %.3g from the sharp union's "
      "(around the intersection circle)" % moved)
check(moved > 0.02, "bernhardt Fig. 6: the local union blends around the intersection")
drops = [scene("bernhardt-drop-%02d.json" % i) for i in range(12)]
touching, necks = 0, []
for d in drops:
    f = Field(d)
    sh = Field(with_root(d, {"type": "max", "args": d["root"]["args"]}))
    y = d["root"]["args"][0]["center"][1]
    gap = y - 0.5  # the drop's bottom above the water's top (y = 0)
    P = f.mesh(96)
    moved = sh.distance(P).max()
    print("Fig. 8 (bernhardt): drop centre y = %.3g (gap %.3g): the surface lies up to %.3g from "
          "the two spheres' sharp union" % (y, gap, moved))
    if gap > 0:
        check(moved < 1e-6, "bernhardt Fig. 8: a drop above the water stays a sphere (y = %g)" % y)
    elif gap < 0:
        touching += 1
        necks.append(moved)
        check(moved > 0.005, "bernhardt Fig. 8: a drop in the water joins it with a neck (y = %g)"
              % y)
check(touching >= 3, "bernhardt Fig. 8: the sweep has drops in the water (%d)" % touching)
check(all(b > a for a, b in zip(necks, necks[1:])), "bernhardt Fig. 8: the neck grows as the drop "
      "sinks: %s" % ", ".join("%.3g" % v for v in necks))

print("test_figures: %d checks passed" % checks)
