"""Animation in headless Blender, rendered the way farms render: a saved
.blend rendered by another Blender with `blender -b FILE -a` (and -s / -e /
-j ranges, and -f), the add-on enabled with --addons.

    blender -b --factory-startup --python-exit-code 1 --python test_animation.py -- \
        ADDON BLENDTOOL SOURCE_DIR WORK_DIR

The field: a sharp union of a static sphere and a blend A of a blend B (two
spheres, r keyframed, one sphere moving) with a fourth sphere; B's m is
driven by a custom property of a controller object, itself keyframed, so m
moves B's reach on A. Checked:
  - the scene exported at each frame holds that frame's keyed, moved and
    driven values (computed here independently);
  - each rendered frame's mesh equals `blendtool mesh` of that export
    (vertex count, volume within 1e-6);
  - consecutive rendered frames differ, and only inside the screen area the
    changing part covers; the static sphere's pixels are identical;
  - -s 2 -e 4 -j 2 renders frames 2 and 4 only, -f 3 frame 3, identical to
    the full run's;
  - a bake writes one file per frame (no temporary files left), a render
    from it without any library gives the same meshes and images, a change
    after the bake makes the frame stale (meshed, not read), a damaged file
    is reported;
  - scrubbing a baked field reads its frame at once; a driver changed
    interactively marks the field dirty and the live path meshes its value;
  - blender_addon_c/examples/headless_render.py runs and does what it says.
ADDON: the folder holding libblend_blender/, or ext:MODULE (addon_env.py).
"""
import glob
import json
import os
import subprocess
import sys
import time

import addon_utils
import bpy
import mathutils
import numpy as np
from bpy_extras.object_utils import world_to_camera_view

argv = sys.argv[sys.argv.index("--") + 1:]
ADDON, BLENDTOOL, SRC, WORK = argv[:4]
os.makedirs(WORK, exist_ok=True)
sys.path.insert(0, os.path.join(SRC, "tests", "mesh"))
sys.path.insert(0, os.path.join(SRC, "tests", "blender"))
import meshcheck  # noqa: E402
import addon_env  # noqa: E402

os.environ.pop("LIBBLEND_LIBRARY", None)
lbb, ADDON_NAME = addon_env.enable(ADDON)
libhandle, live, tree, bake = lbb.libhandle, lbb.live, lbb.tree, lbb.bake
print("Blender %s, add-on %s" % (bpy.app.version_string, ADDON_NAME))
check, active, activate = addon_env.check, addon_env.active, addon_env.activate
# the viewport meshes below are compared with unsimplified library meshes
check(addon_env.viewport_simplify_off(lbb) == 0.5, "Viewport Simplify ships at 0.5 cells")


def linear(obj, path):
    for fc in obj.animation_data.action.fcurves:
        if fc.data_path == path:
            for k in fc.keyframe_points:
                k.interpolation = "LINEAR"


# ---------------------------------------------------------------- the animated field
sc = bpy.context.scene
for o in list(sc.objects):
    bpy.data.objects.remove(o)
bpy.ops.libblend.add_field(convention="zero", with_sphere=False)
out = active()
out.name = "anim"
s = out.libblend
s.live = False
s.bounds_min, s.bounds_max = (-4.0, -1.6, -1.6), (3.0, 1.6, 1.6)
s.preview_resolution, s.render_resolution = 20, 44
bpy.ops.libblend.add_blend(blend_type="min")
root = active()
bpy.ops.libblend.add_blend(blend_type="displacement", op="union")
A = active()
A.libblend.r = 0.5
bpy.ops.libblend.add_blend(blend_type="displacement", op="union")
B = active()
bpy.ops.libblend.add_primitive(prim_type="sphere")
s1 = active()
s1.libblend.radius = 0.7
bpy.ops.libblend.add_primitive(prim_type="sphere", location=(1.0, 0, 0))
s2 = active()
s2.libblend.radius = 0.6
activate(A)
bpy.ops.libblend.add_primitive(prim_type="sphere", location=(0.5, 0.9, 0))
s4 = active()
s4.libblend.radius = 0.5
activate(root)
bpy.ops.libblend.add_primitive(prim_type="sphere", location=(-3.0, 0, 0))
s3 = active()
s3.libblend.radius = 0.6
check(tree.children(root) == [A, s3] and tree.children(A) == [B, s4] and
      tree.children(B) == [s1, s2], "the tree as built")

# keyframes (linear), and a driver: B.m = controller["m"]
FRAMES = (1, 2, 3, 4)
sc.frame_start, sc.frame_end = 1, 4
ctl = bpy.data.objects.new("controller", None)
sc.collection.objects.link(ctl)
ctl["m"] = 1.0
for f, r, x, m in ((1, 0.05, 1.0, 1.0), (4, 1.25, 1.6, 0.4)):
    B.libblend.r = r
    B.keyframe_insert("libblend.r", frame=f)
    s2.location.x = x
    s2.keyframe_insert("location", index=0, frame=f)
    ctl["m"] = m
    ctl.keyframe_insert('["m"]', frame=f)
linear(B, "libblend.r")
linear(s2, "location")
linear(ctl, '["m"]')
drv = B.driver_add("libblend.m").driver
drv.type = "AVERAGE"
var = drv.variables.new()
var.type = "SINGLE_PROP"
var.targets[0].id = ctl
var.targets[0].data_path = '["m"]'


# every setting that shapes a field takes keyframes and drivers
shaping = [p for p in s.bl_rna.properties if p.type in ("FLOAT", "INT", "BOOLEAN", "ENUM")
           and p.identifier not in ("kind", "role", "order", "live", "use_bake", "normals",
                                    "preview_resolution", "render_resolution")]
check(len(shaping) > 30 and all(p.is_animatable for p in shaping),
      "not animatable: %s" % [p.identifier for p in shaping if not p.is_animatable])


def expected(f):
    t = (f - 1) / 3.0
    return {"r": 0.05 + 1.2 * t, "x": 1.0 + 0.6 * t, "m": 1.0 - 0.6 * t}


# camera, sun from the static sphere's side, no world light, direct light only
cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
sc.collection.objects.link(cam)
cam.location = (-0.5, -9.0, 1.0)
cam.rotation_euler = (1.46, 0, 0)
sc.camera = cam
sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
sc.collection.objects.link(sun)
sun.rotation_euler = (0.3, -1.0, 0)  # light comes from -x: no shadow of the blend on s3
sun.data.angle = 0.0
sc.world = bpy.data.worlds.new("black")
sc.world.color = (0, 0, 0)
sc.render.engine = "CYCLES"
sc.cycles.samples = 1
sc.cycles.use_denoising = False
sc.cycles.max_bounces = 0
sc.render.resolution_x, sc.render.resolution_y = 112, 48
sc.render.resolution_percentage = 100
sc.render.image_settings.file_format = "PNG"
sc.render.filepath = os.path.join(WORK, "full", "f_")
sc.frame_set(1)
blend_path = os.path.join(WORK, "anim.blend")
bpy.ops.wm.save_as_mainfile(filepath=blend_path)

# ---------------------------------------------------------------- the exports, frame by frame
exports = {}
for f in FRAMES:
    sc.frame_set(f)
    # what Export writes: with Fit Region (Add's fields) the fitted region as the bounds
    text, _p, _lo, _hi, cell = live.scene_text(out, bpy.context.evaluated_depsgraph_get())
    js = json.loads(text)
    e = expected(f)
    b = js["root"]["args"][0]["args"][0]
    got = {"r": b["r"], "x": b["args"][1]["translate"][0], "m": b["m"]}
    print("frame %d export: %s (expected %s)" % (f, got, e))
    for k in e:
        check(abs(got[k] - e[k]) < 2e-6, "frame %d: %s = %r, expected %r" % (f, k, got[k], e[k]))
    path = os.path.join(WORK, "frame-%d.json" % f)
    with open(path, "w") as fh:
        fh.write(text)
    ply = path[:-5] + ".ply"
    grid = ["--cell-size", repr(cell)] if cell else ["--resolution", "44"]
    subprocess.run([BLENDTOOL, "mesh", path, "-o", ply, "--quiet"] + grid, check=True)
    V, _N, F = meshcheck.read(ply)
    exports[f] = meshcheck.check(V, F)
sc.frame_set(1)

# ---------------------------------------------------------------- blender -b FILE -a, for real
BL, ENV = addon_env.blender_cmd(ADDON, WORK)


def render(name, args, env=None):
    """Render the saved file in a new Blender; returns ({frame: mesh info}, {frame: pixels}, log)."""
    dump = os.path.join(WORK, name, "meshes")
    e = dict(env or ENV, LB_DUMP_DIR=dump)
    t0 = time.perf_counter()
    r = subprocess.run(BL + [blend_path, "--python", os.path.join(SRC, "tests", "blender",
                                                                   "render_hook.py"),
                             "-o", os.path.join(WORK, name, "f_")] + args,
                       env=e, capture_output=True, text=True)
    check(r.returncode == 0, "%s: blender %s failed:\n%s" % (name, args, r.stderr[-2000:]))
    meshes, images = {}, {}
    for p in sorted(glob.glob(os.path.join(dump, "anim_*.npz"))):
        z = np.load(p)
        meshes[int(p[-8:-4])] = meshcheck.check(z["V"].astype(np.float64), z["F"].astype(np.int64))
    for p in sorted(glob.glob(os.path.join(WORK, name, "f_*.png"))):
        images[int(p[-8:-4])] = addon_env.image_pixels(p)
    print("%s: frames %s in %.1f s" % (name, sorted(images), time.perf_counter() - t0))
    return meshes, images, r.stdout


full_m, full_i, _log = render("full", ["-a"])
check(sorted(full_m) == list(FRAMES) and sorted(full_i) == list(FRAMES), "all 4 frames rendered")
for f in FRAMES:
    ir, ib = full_m[f], exports[f]
    print("frame %d: rendered %d vertices, volume %.7f; blendtool %d, %.7f"
          % (f, ir["vertices"], ir["volume"], ib["vertices"], ib["volume"]))
    check(ir["closed"] and ir["manifold"], "frame %d: closed and manifold" % f)
    check(ir["vertices"] == ib["vertices"] and abs(ir["volume"] - ib["volume"]) <= 1e-6 * ib["volume"],
          "frame %d renders the mesh of that frame's scene" % f)


# where the frames may differ: the screen box of the changing part (x > -2) in
# both frames, two pixels wider; the static sphere s3 (x < -2) must not change
def screen_box(frames, sel):
    W, H = sc.render.resolution_x, sc.render.resolution_y
    pts = []
    for f in frames:
        z = np.load(os.path.join(WORK, "full", "meshes", "anim_%04d.npz" % f))
        V = z["V"].astype(np.float64)
        pts.append(V[sel(V)])
    P = np.concatenate(pts)
    uv = np.array([world_to_camera_view(sc, cam, out.matrix_world @ mathutils.Vector(p))[:2]
                   for p in P[::max(1, len(P) // 3000)]])
    x0, y0 = np.floor(uv.min(0) * [W, H]) - 2
    x1, y1 = np.ceil(uv.max(0) * [W, H]) + 2
    return int(max(0, x0)), int(max(0, y0)), int(min(W, x1)), int(min(H, y1))


changing = screen_box(FRAMES, lambda V: V[:, 0] > -2)
static = screen_box(FRAMES, lambda V: V[:, 0] < -2)
check(static[2] < changing[0], "the static sphere's screen box is apart: %s %s" % (static, changing))
sx0, sy0, sx1, sy1 = static
lit = full_i[1][sy0:sy1, sx0:sx1, :3].max(axis=2) > 0.05
check(lit.sum() > 30, "the static sphere is visible and lit (%d pixels)" % lit.sum())
for a, b in zip(FRAMES, FRAMES[1:]):
    d = np.abs(full_i[a] - full_i[b]).max(axis=2) > 1e-4
    x0, y0, x1, y1 = screen_box((a, b), lambda V: V[:, 0] > -2)
    inside = np.zeros_like(d)
    inside[y0:y1, x0:x1] = True
    print("frames %d -> %d: %d pixels differ, %d outside the changing part's box"
          % (a, b, d.sum(), (d & ~inside).sum()))
    check(d.sum() > 30, "frames %d and %d differ" % (a, b))
    check(not (d & ~inside).any(), "frames %d and %d differ only where the field changed" % (a, b))
    check(np.array_equal(full_i[a][sy0:sy1, sx0:sx1], full_i[b][sy0:sy1, sx0:sx1]),
          "the static sphere's pixels are identical in frames %d and %d" % (a, b))

# frame ranges: -s -e -j, and -f
part_m, part_i, _ = render("range", ["-s", "2", "-e", "4", "-j", "2", "-a"])
check(sorted(part_i) == [2, 4] and sorted(part_m) == [2, 4], "-s 2 -e 4 -j 2: frames 2 and 4 "
      "only (%s)" % sorted(part_i))
one_m, one_i, _ = render("single", ["-f", "3"])
check(sorted(one_i) == [3], "-f 3: frame 3 only")
# motion blur: Cycles steps through sub-frames 2.75 and 3.25; the frame renders the
# frame's own shape (the field's object does not move, so nothing blurs)
blur_m, blur_i, _ = render("blur", ["--python-expr", "import bpy; bpy.context.scene.render."
                                    "use_motion_blur = True", "-f", "3"])
check(blur_m[3]["vertices"] == full_m[3]["vertices"] and blur_m[3]["volume"] == full_m[3]["volume"],
      "motion blur: frame 3 renders frame 3's mesh, not a sub-frame's")
# ... with velocities from libblend (the point attribute `velocity`, units per
# second): zero on the static sphere s3 (a sharp union, far from the rest);
# on s2's far cap (x = 2.0 at frame 3, outside every blend's range) the
# sphere's own motion, 0.6 / 3 units a frame x 24 fps = 4.8 units/s along x
z = np.load(os.path.join(WORK, "blur", "meshes", "anim_0003.npz"))
if check("U" in z.files, "motion blur: the rendered mesh has a velocity attribute"):
    V, U = z["V"].astype(np.float64), z["U"].astype(np.float64)
    static = V[:, 0] < -2.0
    check(static.any() and np.abs(U[static]).max() < 1e-6,
          "motion blur: the static sphere's vertices do not move: %g" % np.abs(U[static]).max())
    # the cap's vertices (x > 1.75; s2's centre is at x = 1.4 at frame 3):
    # the normal motion of a sphere moving at s along x, (s . n) n
    cap = V[:, 0] > 1.75
    speed = 0.6 / 3 * bpy.context.scene.render.fps
    n = V[cap] - (1.4, 0, 0)
    n /= np.linalg.norm(n, axis=1)[:, None]
    expect = speed * n[:, :1] * n
    err = np.linalg.norm(U[cap] - expect, axis=1).max() / speed if cap.any() else 1.0
    print("motion blur: %d vertices on s2's far cap; velocity error at most %.2g of the speed "
          "%.2f units/s" % (cap.sum(), err, speed))
    check(cap.sum() >= 10 and err < 0.01, "motion blur: s2's far cap's velocities %.3g of the "
          "speed from (s . n) n (bar 1 %%)" % err)
for f, (mm, ii) in {2: (part_m, part_i), 4: (part_m, part_i), 3: (one_m, one_i)}.items():
    check(mm[f]["vertices"] == full_m[f]["vertices"] and mm[f]["volume"] == full_m[f]["volume"],
          "frame %d: the same mesh in a range render" % f)
    check(np.array_equal(ii[f], full_i[f]), "frame %d: the same image in a range render" % f)

# ---------------------------------------------------------------- bake
activate(out)
os.umask(0o022)  # so that the mode check below tells 0644 from mkstemp's 0600
check(bpy.ops.libblend.bake(frame_start=1, frame_end=4) == {"FINISHED"}, "bake")
folder = bake.folder(out)
check(folder == os.path.join(WORK, "libblend_cache", "anim"), "next to the .blend: " + folder)
check(bake.frames(folder) == list(FRAMES), "one file per frame: %s" % bake.frames(folder))
check(not [n for n in os.listdir(folder) if not n.startswith("frame_")], "no temporary files")
print("bake:", out.libblend.bake_info)
# a render node running as another user reads the bake: the files' mode is
# 0666 less the umask, as any Unix tool's (mkstemp alone leaves 0600)
_umask = os.umask(0o022)
os.umask(_umask)
for f in FRAMES:
    mode = os.stat(bake.frame_path(folder, f)).st_mode & 0o777
    check(mode == 0o666 & ~_umask, "baked frame %d mode %o, expected %o" % (f, mode, 0o666 & ~_umask))
for f in FRAMES:
    c = bake.read(bake.frame_path(folder, f))
    i = meshcheck.check(c.positions.astype(np.float64), c.triangles.astype(np.int64))
    check(i["vertices"] == full_m[f]["vertices"] and abs(i["volume"] - full_m[f]["volume"]) < 1e-6
          * full_m[f]["volume"], "baked frame %d = the rendered mesh" % f)
check(out.libblend.use_bake, "the field uses its bake")
bpy.ops.wm.save_mainfile()
# a farm without the library: the bake is all it needs
no_lib = dict(ENV, LIBBLEND_LIBRARY=os.path.join(WORK, "no-such", "libblend.so"))
bm, bi, log = render("baked", ["-a"], no_lib)
check(sorted(bi) == list(FRAMES), "baked render: 4 frames")
check("meshed instead" not in log, "no frame meshed: " + log[-500:])
for f in FRAMES:
    check(bm[f]["vertices"] == full_m[f]["vertices"] and
          abs(bm[f]["volume"] - full_m[f]["volume"]) <= 1e-6 * full_m[f]["volume"],
          "baked frame %d renders the same mesh" % f)
    check(np.abs(bi[f] - full_i[f]).max() <= 1 / 255 + 1e-6, "baked frame %d renders the same image" % f)

# scrubbing a baked field reads the frame's file at once (no timer in the background)
sc.frame_set(3)
check(len(out.data.vertices) == full_m[3]["vertices"], "frame 3 shown from the bake")
check("from the bake" in live.state_of(out).status, live.state_of(out).status)
# a change after the bake: that state is not in the bake
s3.libblend.radius = 0.65
used, note = live.from_cache(out, 3)
check(not used and "changed since the bake" in note, "stale frame refused: " + note)
s3.libblend.radius = 0.6
check(live.from_cache(out, 3)[0], "back to the baked state: used again")
# a damaged file is named, with the fix
with open(bake.frame_path(folder, 2), "wb") as fh:
    fh.write(b"not a bake")
try:
    bake.read(bake.frame_path(folder, 2))
    check(False, "a damaged bake file must be refused")
except bake.CacheError as e:
    check("frame_000002.npz" in str(e) and "bake again" in str(e), "damaged file reported: %s" % e)
sc.frame_set(2)  # its frame change finds the file damaged and leaves the mesh
check(len(out.data.vertices) == full_m[3]["vertices"], "a damaged frame is not applied")
used, note = live.from_cache(out, 2)
check(not used and "frame_000002.npz" in note, "from_cache reports it: " + note)
ok, msg = live.frame_update(out, 2)
check(ok and len(out.data.vertices) == full_m[2]["vertices"], "and meshes the frame instead")
activate(out)
check(bpy.ops.libblend.bake_clear() == {"FINISHED"} and not os.path.exists(folder) and
      not out.libblend.use_bake, "clear bake")

# ---------------------------------------------------------------- scrubbing, live
# a frame change outside a render marks the field dirty; the live path meshes
# that frame's state at preview resolution
out.libblend.live = True
live.update_now(out)
n_before = len(out.data.vertices)
sc.frame_set(3)
check(live.state_of(out).dirty, "a frame change marks the live field dirty")
while live.tick() is not None:
    time.sleep(0.002)
text2, _p, lo2, hi2, c2 = live.scene_text(out, bpy.context.evaluated_depsgraph_get(),
                                             resolution=s.preview_resolution)
with libhandle.library().parse_scene(text2) as scn, scn.compile() as ev:
    ref2 = ev.mesh(lo2, hi2, resolution=s.preview_resolution, cell_size=c2)
check(len(out.data.vertices) == len(ref2.positions) != n_before and
      abs(json.loads(text2)["root"]["args"][0]["args"][0]["r"] - expected(3)["r"]) < 2e-6,
      "scrubbing from frame 2 to 3 shows frame 3 at preview resolution")
out.libblend.live = False

# ---------------------------------------------------------------- a driver, live
sc.frame_set(4)
live.update_now(out)
check(live.state_of(out).dirty is False, "idle")
out.libblend.live = True
ctl["m"] = 0.55  # no frame change: the driver alone carries it to B's m
ctl.update_tag()
bpy.context.view_layer.update()
check(abs(B.libblend.m - 0.55) < 1e-6, "the driver set m = %r" % B.libblend.m)
check(live.state_of(out).dirty, "a driven change marks the field dirty")
while live.tick() is not None:
    time.sleep(0.002)
st = live.state_of(out)
check(not st.error and not st.dirty, st.status)
text, _p, lo4, hi4, c4 = live.scene_text(out, resolution=s.preview_resolution)
check(abs(json.loads(text)["root"]["args"][0]["args"][0]["m"] - 0.55) < 1e-6, "exported m follows")
with libhandle.library().parse_scene(text) as scn, scn.compile() as ev:
    ref = ev.mesh(lo4, hi4, resolution=s.preview_resolution, cell_size=c4)
check(len(out.data.vertices) == len(ref.positions), "the live mesh is the driven state's")
# an update that changes nothing is not meshed again
t_applied = st.t_applied
cam.location.x += 0.1  # not a node
bpy.context.view_layer.update()
s4.location.y += 0.0
s4.update_tag()
bpy.context.view_layer.update()
while live.tick() is not None:
    time.sleep(0.002)
check(live.state_of(out).t_applied == t_applied, "an update that changes no value does not remesh")

# ---------------------------------------------------------------- the headless scripting example
ex = os.path.join(WORK, "example")
r = subprocess.run(BL + ["--python", os.path.join(SRC, "blender_addon_c", "examples",
                                                   "headless_render.py"), "--", ex],
                   env=ENV, capture_output=True, text=True)
check(r.returncode == 0 and "headless_render:" in r.stdout, "the example runs: " + r.stderr[-1500:])
summ = json.load(open(os.path.join(ex, "summary.json")))
print("example:", summ)
img1, img3 = (addon_env.image_pixels(os.path.join(ex, "frame_%04d.png" % f)) for f in (1, 3))
check(np.abs(img1 - img3).max() > 0.1, "its two frames differ")
ply = os.path.join(ex, "frame_0003.ply")
cell = summ.get("frame 3 cell (render)", 0)
check(cell > 0, "the example's field fits its region (Fit Region): cell %r" % cell)
subprocess.run([BLENDTOOL, "mesh", os.path.join(ex, "frame_0003.json"), "-o", ply, "--cell-size",
                repr(cell), "--quiet"], check=True)
V, _N, F = meshcheck.read(ply)
check(len(F) == summ["frame 3 triangles (render)"], "frame 3 rendered the exported scene's mesh")
check(summ["frame 1 triangles (render)"] == summ["frame 1 triangles (update_mesh)"],
      "update_mesh(final=True) = what the render meshes")
check(bake.frames(os.path.join(ex, "libblend_cache", "field")) == [1, 2, 3], "the example baked")

# ---------------------------------------------------------------- Apply after a script removed objects
# (Blender 4.3 leaves the view layer's bases stale until it resyncs: selection
# code must not trip over them)
for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
check(bpy.ops.libblend.import_scene(filepath=os.path.join(SRC, "scenes", "bench-s2-64-spheres.json"),
                                    with_render=False) == {"FINISHED"}, "import S2")
big = active()
big.select_set(True)
check(bpy.ops.libblend.apply(resolution=24) == {"FINISHED"} and active().type == "MESH" and
      active().libblend.kind == "NONE", "Apply a 66-object field after objects were removed")

addon_utils.disable(ADDON_NAME)
print("test_animation: %d checks passed" % addon_env.checks)
