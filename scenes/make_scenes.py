#!/usr/bin/python3
"""Writes the paper-figure and benchmark scenes in this folder.

The papers give the CSG trees and the parameters that vary (m, bulge
elimination, bounding solids) but not every size and position; those are
chosen here once, so the variants of one figure differ only in what the
figure varies. Run it after changing a figure: `scenes/make_scenes.py`.
"""
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def camera(location, look_at, angle=35, up=None):
    c = {"location": location, "look_at": look_at, "angle": angle}
    if up:
        c["up"] = up
    return c


# Scenes are right-handed with z up. Each figure gets a camera that shows
# what the figure is about (the comment at each figure says what); the
# lights are the exporters' three-point default around that camera, over a
# floor (docs/scene-format.md, Render section).
THREE_QUARTER = camera([4.0, -6.0, 4.5], [0, 0, 0])


def scene(title, description, convention, root, bounds, defs=None, cam=THREE_QUARTER):
    s = {"format": "libblend-scene", "version": 1, "title": title,
         "description": description, "convention": convention,
         "bounds": {"min": bounds[0], "max": bounds[1]}}
    if defs:
        s["defs"] = defs
    s["root"] = root
    s["render"] = {
        "camera": cam,
        "material": {"color": [0.85, 0.7, 0.45], "ambient": 0.1, "diffuse": 0.7,
                     "specular": 0.3}}
    return s


def write(name, s):
    with open(os.path.join(HERE, name), "w") as f:
        json.dump(s, f, indent=2)
        f.write("\n")


def slab(axis, half_width=1.0, center=(0, 0, 0), kernel=None):
    n = [0, 0, 0]
    n[axis] = 1
    node = {"type": "slab", "point": list(center), "normal": n, "half_width": half_width}
    if kernel:
        node["kernel"] = kernel
    return node


def halfspace(normal, offset):
    """inside: normal . X < offset (|normal| = 1, width 1)"""
    return {"type": "halfspace", "point": [normal[i] * (offset - 1.0) for i in range(3)],
            "normal": list(normal), "width": 1.0}


B2 = ([-2.2, -2.2, -2.2], [2.2, 2.2, 2.2])

# hsu2006 Fig. 7: S(-BT3(-f1,-f2,-f3), 0) (rounded cube) in union with a
# super-ellipsoid; m2 of the cube's f2 (the y slab, facing the
# super-ellipsoid) is lowered 1.2, 0.9, 0.6, 0.3: only f2's subsequent
# blend with the super-ellipsoid shrinks, the cube itself does not change.
for m2 in (1.2, 0.9, 0.6, 0.3):
    cube = {"type": "displacement", "op": "intersection",
            "args": [slab(0), slab(1), slab(2)], "r": 0.3, "p": 2, "m": [1, m2, 1]}
    blob = {"type": "superquadric", "center": [0.0, 1.35, 0.0], "semi_axes": [0.55, 0.55, 0.55],
            "e1": 0.6, "e2": 0.6}
    root = {"type": "displacement", "op": "union", "args": [cube, blob], "r": 0.45, "p": 2}
    write("hsu2006-fig7-m%s.json" % m2, scene(
        "hsu2006 Fig. 7, m2 = %s" % m2,
        "BT2(S(-BT3(-f1,-f2,-f3)), super-ellipsoid) with m2 = %s for the cube's f2" % m2,
        # from the +x side: the cube on the left, the super-ellipsoid on the
        # right, the blend between them in profile
        "zero", root, B2, cam=camera([7.5, 0.6, 2.2], [0, 0.6, -0.1], 34)))

# hsu2006 Fig. 8: S(-BT2(-b2, b1), 0): the six-plane box b2 (a slot) cut
# from the six-plane box b1. The slot floor f12 is 0.35 below the top face
# f6, closer than the difference's range 0.5: with m = 1 they blend
# (unwanted); lowering m6 and m12 to 0.3 removes it, b1 and b2 unchanged.
for tag, mlow in (("plain", 1.0), ("lowered-m", 0.3)):
    b1 = {"type": "displacement", "op": "intersection", "r": 0.2, "p": 2,
          "m": [1, 1, 1, 1, 1, mlow],
          "args": [halfspace((1, 0, 0), 1), halfspace((-1, 0, 0), 1),
                   halfspace((0, 1, 0), 1), halfspace((0, -1, 0), 1),
                   halfspace((0, 0, -1), 1), halfspace((0, 0, 1), 1)]}
    b2 = {"type": "displacement", "op": "intersection", "r": 0.2, "p": 2,
          "m": [1, 1, 1, 1, 1, mlow],
          "args": [halfspace((1, 0, 0), 0.45), halfspace((-1, 0, 0), 0.45),
                   halfspace((0, 1, 0), 1.6), halfspace((0, -1, 0), 1.6),
                   halfspace((0, 0, 1), 1.6), halfspace((0, 0, -1), -0.65)]}
    root = {"type": "displacement", "op": "difference", "args": [b1, b2], "r": 0.5, "p": 2}
    write("hsu2006-fig8-%s.json" % tag, scene(
        "hsu2006 Fig. 8, %s" % tag,
        "difference of two six-plane intersections, m6 = m12 = %s" % mlow,
        # down the slot from the front and above: its floor and the top face
        "zero", root, B2, cam=camera([1.4, -6.5, 3.6], [0, 0, 0.3], 30)))

# hsu2006 Fig. 9: the wheel S(BT2(BT2(f1, f2), f3), 0): crossing spokes f1,
# f2 joined with bulge elimination, then the toroidal rim f3; m1 = 1 and 0.3
# change only f1's corners at the rim, not the joint of the spokes.
for m1 in (1, 0.3):
    spokes = {"type": "displacement", "op": "union", "r": 0.3, "p": 2, "m": [m1, 1],
              "bulge": {"range": True, "slope": False, "omega": 0.001},
              "args": [{"type": "cylinder", "point": [0, 0, 0], "axis": [1, 0, 0], "radius": 0.18},
                       {"type": "cylinder", "point": [0, 0, 0], "axis": [0, 1, 0], "radius": 0.18}]}
    rim = {"type": "torus", "center": [0, 0, 0], "axis": [0, 0, 1], "major_radius": 1.4,
           "minor_radius": 0.2}
    # the spokes end at the rim: intersect them with a slab-bounded disc
    disc = {"type": "cylinder", "point": [0, 0, 0], "axis": [0, 0, 1], "radius": 1.45}
    spokes_in = {"type": "max", "args": [spokes, disc]}
    root = {"type": "displacement", "op": "union", "r": 0.3, "p": 2,
            "args": [spokes_in, rim]}
    write("hsu2006-fig9-m%s.json" % m1, scene(
        "hsu2006 Fig. 9, m1 = %s" % m1,
        "wheel BT2(BT2(f1, f2) with bulge elimination, f3), m1 = %s" % m1,
        # close on the +x spoke's joint with the rim, where m1 acts, with the
        # hub (which must not change) in view
        "zero", root, ([-1.9, -1.9, -0.6], [1.9, 1.9, 0.6]),
        cam=camera([2.8, -3.4, 3.4], [0.8, 0.2, 0], 38)))

# hsu-bounded Fig. 2: the wheel B_D2(B_U2(B_U2(f1, f2), f3), f4) by the
# scale method: spokes f1, f2, rim f3, axle hole f4.
spokes = {"type": "scale", "op": "union", "r": 0.4, "p": 2,
          "args": [{"type": "capsule", "start": [-1.3, 0, 0], "end": [1.3, 0, 0], "radius": 0.16},
                   {"type": "capsule", "start": [0, -1.3, 0], "end": [0, 1.3, 0], "radius": 0.16}]}
wheel = {"type": "scale", "op": "union", "r": 0.3, "p": 2,
         "args": [spokes, {"type": "torus", "center": [0, 0, 0], "axis": [0, 0, 1],
                           "major_radius": 1.35, "minor_radius": 0.18}]}
root = {"type": "scale", "op": "difference", "r": 0.3, "p": 2,
        "args": [wheel, {"type": "cylinder", "point": [0, 0, 0], "axis": [0, 0, 1],
                         "radius": 0.07}]}
write("hsu-bounded-fig2-wheel.json", scene(
    "hsu-bounded Fig. 2, wheel", "B_D2(B_U2(B_U2(f1, f2), f3), f4) by the scale method",
    # from above at a slant: spokes, rim and axle hole
    "zero", root, ([-1.8, -1.8, -0.6], [1.8, 1.8, 0.6]),
    cam=camera([0.9, -3.2, 4.6], [0.1, 0, 0], 40)))

# hsu-bounded Fig. 7: a stool, four legs and a plate in one bounded union;
# the plate's bounding solid keeps its blending region off the corners.
legs = []
leg_bounds = []
for sx in (-1, 1):
    for sy in (-1, 1):
        legs.append({"type": "capsule", "start": [0.55 * sx, 0.55 * sy, -1.2],
                     "end": [0.55 * sx, 0.55 * sy, 0.2], "radius": 0.1})
        leg_bounds.append({"type": "capsule", "start": [0.55 * sx, 0.55 * sy, -1.2],
                           "end": [0.55 * sx, 0.55 * sy, 0.2], "radius": 0.35})
plate = {"type": "ellipsoid", "center": [0, 0, 0.25], "semi_axes": [1.0, 1.0, 0.12]}
plate_bound = {"type": "ellipsoid", "center": [0, 0, 0.25], "semi_axes": [1.0, 1.0, 0.4]}
root = {"type": "bounded", "op": "union", "p": 2, "args": [plate] + legs,
        "bounds": [plate_bound] + leg_bounds}
write("hsu-bounded-fig7-stool.json", scene(
    "hsu-bounded Fig. 7, stool with a bounded plate",
    "bounded union of a plate and four legs; the plate's bounding solid is a taller ellipsoid",
    # from the side and a little below the plate: the leg joints
    "zero", root, ([-1.4, -1.4, -1.5], [1.4, 1.4, 0.8]),
    cam=camera([4.6, -3.4, -0.5], [0, 0, -0.35], 38)))

# hsu-bounded Fig. 8: a bounding solid shapes the contour of a union's
# transition. A column stands on a plate in one bounded union; the plate's
# bounding solid is a taller box, so the column blends into the plate
# wherever its own bounding solid reaches: the fillet's footprint on the
# plate takes that solid's cross-section (round, square, elliptical). The
# plain scale-method union, unbounded, is the reference.
column = {"type": "capsule", "start": [0, 0, -0.1], "end": [0, 0, 1.0], "radius": 0.25}
board = {"type": "superquadric", "center": [0, 0, 0], "semi_axes": [1.4, 1.4, 0.15],
         "e1": 0.1, "e2": 0.1}
board_bound = {"type": "superquadric", "center": [0, 0, 0], "semi_axes": [1.45, 1.45, 0.6],
               "e1": 0.1, "e2": 0.1}
contour_bounds = {
    "round": {"type": "capsule", "start": [0, 0, -0.1], "end": [0, 0, 1.0], "radius": 0.6},
    "square": {"type": "superquadric", "center": [0, 0, 0.45], "semi_axes": [0.6, 0.6, 0.9],
               "e1": 0.1, "e2": 0.1},
    "ellipse": {"type": "ellipsoid", "center": [0, 0, 0.5], "semi_axes": [0.95, 0.4, 1.0]},
}
contour_cam = camera([2.3, -3.1, 2.6], [0, 0, 0.15], 36)
write("hsu-bounded-fig8-plain.json", scene(
    "hsu-bounded Fig. 8, plain union",
    "a column on a plate, the scale method's union without bounding solids (r = 0.35)",
    "zero", {"type": "scale", "op": "union", "r": 0.35, "p": 2, "args": [board, column]},
    ([-1.6, -1.6, -0.4], [1.6, 1.6, 1.4]), cam=contour_cam))
for shape, cb in contour_bounds.items():
    write("hsu-bounded-fig8-%s.json" % shape, scene(
        "hsu-bounded Fig. 8, %s bound" % shape,
        "a column on a plate in a bounded union; the column's bounding solid (%s) gives the "
        "fillet's contour on the plate" % shape,
        "zero", {"type": "bounded", "op": "union", "p": 2, "args": [board, column],
                 "bounds": [board_bound, cb]},
        ([-1.6, -1.6, -0.4], [1.6, 1.6, 1.4]), cam=contour_cam))

# hsu-nonuniform Fig. 5: the level surfaces B_A3(f1, f2, f3) = h, h = 0.5 to
# 0.3, of a soft intersection of three pairs of planes with m1 = 0.6 and
# m2 = 2.8: the f2 faces (y) dilate farther and faster than the f1 faces
# (x). A level node makes the h-level set the surface.
for h in (0.5, 0.45, 0.4, 0.35, 0.3):
    cube = {"type": "soft_hyper", "op": "intersection", "r": 0.5, "p": 2, "m": [0.6, 2.8, 1],
            "args": [slab(0, kernel="wyvill"), slab(1, kernel="wyvill"), slab(2, kernel="wyvill")]}
    write("hsu-nonuniform-fig5-h%s.json" % h, scene(
        "hsu-nonuniform Fig. 5, h = %s" % h,
        "the level set B_A3(f1, f2, f3) = %s of soft slabs, m1 = 0.6, m2 = 2.8" % h,
        # from above, the +x and -y faces in view
        "soft", {"type": "level", "level": h, "args": [cube]},
        ([-2.4, -2.4, -2.4], [2.4, 2.4, 2.4]), cam=camera([5.0, -6.5, 5.5], [0, 0, 0], 38)))

# hsu-nonuniform Fig. 6: B_S2(B_A3(f1, f2, f3), f4) = 0.5 on soft slabs and a
# soft super-ellipsoid, m2 = 2.8 fixed, m1 = 0.3, 0.65, 1, 1.5.
for m1 in (0.3, 0.65, 1, 1.5):
    cube = {"type": "soft_hyper", "op": "intersection", "r": 0.5, "p": 2, "m": [m1, 2.8, 1],
            "args": [slab(0, kernel="wyvill"), slab(1, kernel="wyvill"), slab(2, kernel="wyvill")]}
    blob = {"type": "superquadric", "center": [1.3, 0.0, 0.9], "semi_axes": [0.6, 0.6, 0.6],
            "e1": 0.6, "e2": 0.6, "kernel": "wyvill"}
    root = {"type": "soft_hyper", "op": "union", "r": 0.6, "p": 2, "args": [cube, blob]}
    write("hsu-nonuniform-fig6-m%s.json" % m1, scene(
        "hsu-nonuniform Fig. 6, m1 = %s" % m1,
        "soft B_S2(B_A3(f1, f2, f3), f4) = 0.5, m1 = %s, m2 = 2.8" % m1,
        # from the front: the cube's +x face and the blob on its top corner
        # in profile
        "soft", root, ([-2.2, -2.2, -2.2], [2.6, 2.2, 2.2]),
        cam=camera([1.2, -7.5, 1.8], [0.5, 0, 0.3], 36)))

# Benchmark scenes (issues 3 and 4). S1: three spheres in one BT_3 union.
S1 = {"type": "displacement", "op": "union", "r": 0.25, "p": 2,
      "args": [{"type": "sphere", "center": c, "radius": 1.0}
               for c in ([0, 0, 0], [1.2, 0, 0], [0, 1.2, 0])]}
write("bench-s1-three-spheres.json", scene(
    "S1: three spheres", "three unit spheres in one BT_3 union, r = 0.25, p = 2", "zero", S1,
    ([-2, -2, -2], [3, 3, 3]), cam=camera([4.5, -5.5, 5.0], [0.4, 0.4, 0], 40)))
# S2: 64 spheres of radius 0.3 on a 4x4x4 lattice of spacing 0.5.
S2 = {"type": "displacement", "op": "union", "r": 0.1, "p": 2,
      "args": [{"type": "sphere", "center": [-0.25 + 0.5 * i, -0.25 + 0.5 * j, -0.25 + 0.5 * k],
                "radius": 0.3} for i in range(4) for j in range(4) for k in range(4)]}
write("bench-s2-64-spheres.json", scene(
    "S2: 64 spheres", "64 spheres (radius 0.3, 4x4x4 lattice, spacing 0.5) in one BT_64 union",
    "zero", S2, ([-2, -2, -2], [3, 3, 3]), cam=camera([4.0, -4.5, 4.0], [0.5, 0.5, 0.45], 36)))

# The README's main job: the hsu2006 Fig. 7 setting with a shared cube def.
cube = {"type": "displacement", "op": "intersection", "args": [slab(0), slab(1), slab(2)],
        "r": 0.3, "p": 2, "m": [1, 0.6, 1]}
root = {"type": "displacement", "op": "union", "r": 0.45, "p": 2,
        "args": [{"ref": "cube"},
                 {"type": "superquadric", "center": [0.0, 1.35, 0.0],
                  "semi_axes": [0.55, 0.55, 0.55], "e1": 0.6, "e2": 0.6},
                 {"ref": "cube", "translate": [0, -2.6, 0], "rotate": [0, 0, 45], "scale": 0.6}]}
write("default.json", scene(
    "libblend default scene",
    "a rounded cube blended with a super-ellipsoid (m2 = 0.6, hsu2006 Fig. 7) and a rotated, "
    "scaled copy of the same cube (a shared def)",
    # from the +x side: the small cube, the cube and the super-ellipsoid in a row
    "zero", root, ([-2.2, -4.0, -2.2], [2.2, 2.2, 2.2]), defs={"cube": cube},
    cam=camera([8.5, -1.6, 3.4], [0, -0.8, -0.2], 40)))

# ---- local blending (Bernhardt, Barthe, Cani, Wyvill 2010): bernhardt-*.json


def soft_sphere(c, r):
    return {"type": "sphere", "center": list(c), "radius": r, "kernel": "wyvill"}


def soft_capsule(a, b, r):
    return {"type": "capsule", "start": list(a), "end": list(b), "radius": r, "kernel": "wyvill"}


WATER = soft_sphere((0, -5, 0), 5.0)  # its top at y = 0
# The local-blending scenes stand along +y (the drop falls in -y): their
# cameras say so with up = +y, and look from +z.
Y_UP = [0, 1, 0]
DROP_CAM = camera([0.9, 1.6, 6.5], [0, 0.15, 0], 34, Y_UP)
DROP_BOUNDS = ([-1.5, -1.0, -1.5], [1.5, 1.6, 1.5])
# the drop (radius 0.5) from well above the water to half under it: no blend
# before it touches (y > 0.5), then a blend that grows with the penetration
for i, y in enumerate([1.0, 0.8, 0.6, 0.52, 0.48, 0.42, 0.36, 0.3, 0.24, 0.18, 0.12, 0.06]):
    write("bernhardt-drop-%02d.json" % i, scene(
        "bernhardt2010 drop on water, position %d of 12 (drop centre y = %g)" % (i + 1, y),
        "a drop of radius 0.5 over water whose surface is at y = 0, under a local union: it "
        "blends only once it touches, more as it goes deeper (seed Fig. 8)",
        "soft", {"type": "local_union", "args": [soft_sphere((0, y, 0), 0.5), WATER]},
        DROP_BOUNDS, cam=DROP_CAM))

# a hand next to the body: closer than any classic blend range, not touching
write("bernhardt-hand-near-body.json", scene(
    "bernhardt2010 hand near the body: no blend",
    "an arm's capsule 0.04 from the body's: the local union is their exact union",
    "soft", {"type": "local_union", "args": [
        soft_capsule((0, -1.2, 0), (0, 1.2, 0), 0.6),
        soft_capsule((0.84, -1.0, 0), (0.84, 0.6, 0.0), 0.2)]},
    ([-1.0, -2.0, -1.0], [1.2, 2.0, 1.0]), cam=camera([1.6, 0.6, 6.0], [0.3, -0.1, 0], 40, Y_UP)))

# several convolution-like primitives blended locally (the paper's dancer)
write("bernhardt-figure.json", scene(
    "bernhardt2010 a figure of capsules blended locally",
    "body, head, arms and legs as soft capsules, a left fold of local unions: each limb "
    "blends only where it enters the body",
    "soft", {"type": "local_union", "args": [
        soft_capsule((0, -0.8, 0), (0, 0.8, 0), 0.35), soft_sphere((0, 1.25, 0), 0.4),
        soft_capsule((-0.2, 0.5, 0), (-1.1, -0.3, 0), 0.15),
        soft_capsule((0.2, 0.5, 0), (1.1, -0.3, 0), 0.15),
        soft_capsule((-0.15, -0.7, 0), (-0.3, -2.2, 0), 0.18),
        soft_capsule((0.15, -0.7, 0), (0.3, -2.2, 0), 0.18)]},
    ([-1.5, -2.6, -1.0], [1.5, 1.8, 1.0]), cam=camera([1.5, 0.4, 8.0], [0, -0.4, 0], 40, Y_UP)))

# the same pair three ways: the classic soft sum, Hsu's BT blend, the local blend
PAIR_BOUNDS = ([-1.6, -1.6, -1.6], [2.8, 1.6, 1.6])
PAIR_CAM = camera([1.0, -7.5, 2.2], [0.6, 0, 0], 36)  # the pair side by side, from the front
write("bernhardt-compare-sum.json", scene(
    "comparison: a sphere and a smaller one, soft sum",
    "the classic soft union: the spheres swell toward each other",
    "soft", {"type": "soft_sum", "args": [soft_sphere((0, 0, 0), 1.0),
                                          soft_sphere((1.5, 0, 0), 0.6)]}, PAIR_BOUNDS,
    cam=PAIR_CAM))
write("bernhardt-compare-bt.json", scene(
    "comparison: the same pair, Hsu's BT_2 blend (r = 0.3)",
    "a displacement blend: the fillet follows the contact, but the range acts at a distance",
    "zero", {"type": "displacement", "op": "union", "r": 0.3, "p": 2, "args": [
        {"type": "sphere", "center": [0, 0, 0], "radius": 1.0},
        {"type": "sphere", "center": [1.5, 0, 0], "radius": 0.6}]}, PAIR_BOUNDS, cam=PAIR_CAM))
write("bernhardt-compare-local.json", scene(
    "comparison: the same pair, local union",
    "blends only around the intersection circle; the exact union elsewhere",
    "soft", {"type": "local_union", "alpha": [0.05, 0.05],
             "args": [soft_sphere((0, 0, 0), 1.0), soft_sphere((1.5, 0, 0), 0.6)]},
    PAIR_BOUNDS, cam=PAIR_CAM))
write("bernhardt-drop-zero.json", scene(
    "drop on water in the zero convention",
    "the same local union with distance-like children (zero_scale 1)",
    "zero", {"type": "local_union", "support_factor": 0.3, "args": [
        {"type": "sphere", "center": [0, 0.3, 0], "radius": 0.5},
        {"type": "sphere", "center": [0, -5, 0], "radius": 5}]}, DROP_BOUNDS, cam=DROP_CAM))
