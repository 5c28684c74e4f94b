"""blendtool batch with outputs.image.renderer "blender" (docs/batch.md,
"Rendering with Blender"), run as a farm runs it, with Blender 3.4 and the
Debian 13 root's Blender 4.3:
- a sweep renders through one worker Blender: every image, the contact
  sheet, the image metadata and the manifest naming the Blender version;
- Cycles on the CPU gives the same bytes run to run and at 1 or 2 threads;
- resume: a rerun skips every task; another sample count re-renders;
- a worker killed mid-render, or while idle between tasks, fails only one
  task (exit 1, the message says it died), the other tasks finish, a rerun
  redoes exactly that task and its image equals the uninterrupted run's;
- two shards in two processes at once, and --task through GNU parallel,
  give the same bytes;
- motion blur: a sphere moving 0.5 units a frame, shutter 1 frame, is
  blurred by 0.5 units (measured on the image's alpha: the length of the
  coverage ramps at the sphere's ends), within 6 %; without motion_blur it
  is not;
- a scene without a camera and a Blender that cannot run are refused with
  messages naming the fix;
- EEVEE renders on Blender 3.4; on 4.3 without OpenGL the task fails
  saying what EEVEE needs;
- an installed blendtool (cmake --install) finds the installed add-on;
- Blender 4.3 (the Debian 13 root) renders a job the same way.
usage: test_farm.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time

import jsonschema

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import args, check, finish, read_ppm  # noqa: E402

BT, SRC, WORK = (os.path.abspath(a) for a in args())
shutil.rmtree(WORK)
os.makedirs(WORK)
SCHEMA = json.load(open(os.path.join(SRC, "docs", "libblend-job.schema.json")))
ADDON = os.path.join(os.path.dirname(os.path.dirname(BT)), "blender_addon")
ENV = dict(os.environ, TMPDIR=WORK, LIBBLEND_BLENDER_ADDON=ADDON)


def run(*cmd, **kw):
    return subprocess.run([str(c) for c in cmd], capture_output=True, text=True, env=ENV, **kw)


def job(name, out, outputs, **extra):
    j = {"format": "libblend-job", "version": 1, "name": name, "outputs": outputs,
         "output_dir": out}
    j.update(extra)
    jsonschema.validate(j, SCHEMA)  # the documented schema takes every job here
    path = os.path.join(WORK, name + "-" + os.path.basename(out) + ".json")
    with open(path, "w") as f:
        json.dump(j, f)
    return path


def files(out, ext=".png"):
    return sorted(f for f in os.listdir(out) if f.endswith(ext)) if os.path.isdir(out) else []


def same_bytes(a, b, names):
    return [n for n in names if open(os.path.join(a, n), "rb").read() !=
            open(os.path.join(b, n), "rb").read()]


def events(stdout):
    return [json.loads(line) for line in stdout.splitlines() if line.startswith("{")]


# ---- a sweep through one worker
DROP = os.path.join(SRC, "scenes", "bernhardt-drop-00.json")
SWEEP = [{"path": "root.args[0].center[1]", "range": {"from": 0.9, "to": 0.1, "count": 4}}]
IMG = {"format": "png", "width": 160, "height": 120, "renderer": "blender", "samples": 8,
       "mesh": 48}
SHEET = {"columns": 4, "cell_width": 80, "cell_height": 60}


def sweep(out, img=IMG, **kw):
    return job("drop", os.path.join(WORK, out), {"image": img, "contact_sheet": SHEET},
               scene=DROP, sweep=SWEEP, **kw)


ref = os.path.join(WORK, "ref")
t0 = time.monotonic()
r = run(BT, "batch", sweep("ref"), "--log-json")
t_ref = time.monotonic() - t0
ev = events(r.stdout)
check(r.returncode == 0, "the sweep: exit %d: %s" % (r.returncode, r.stderr[-2000:]))
names = ["drop_%04d.png" % i for i in range(4)]
check(files(ref) == names + ["drop_sheet.png"], "the sweep's images: %s" % files(ref))
starts = [e for e in ev if e["event"] == "task_end"]
print("sweep: 4 tasks in %.1f s (%s)" % (t_ref, ", ".join("%.2f s" % e["seconds"] for e in starts)))
if files(ref):
    info = subprocess.run(["oiiotool", "--info", "-v", os.path.join(ref, names[1])],
                          capture_output=True, text=True).stdout
    m = re.search(r'libblend:render: "([^"]*)"', info)
    check(m and re.match(r"160x120 Blender 3\.4\.\d+ cycles samples 8 seed 0 mesh 48$", m.group(1)),
          "the image's libblend:render: %s" % (m.group(1) if m else info))
    check('libblend:task: "drop_0001"' in info and "libblend:scene_hash" in info,
          "the image's other metadata: %s" % info)
    man = json.load(open(os.path.join(ref, ".libblend-manifest", "drop_0001.json")))
    ident = json.loads(man["identity"])
    check(ident.get("renderer", {}).get("version", "").startswith("Blender 3.4")
          and ident["renderer"].get("engine") == "cycles" and ident["renderer"].get("samples") == 8,
          "the manifest's renderer: %s" % ident.get("renderer"))
    # the images differ along the sweep (the drop moves): not one image four times
    check(len({open(os.path.join(ref, n), "rb").read() for n in names}) == 4,
          "the four images are not all different")
    # the drop is where the sweep puts it: its image rows move down the sweep
    rows = []
    for n in names:
        ppm = os.path.join(WORK, n + ".ppm")
        subprocess.run(["oiiotool", os.path.join(ref, n), "-o", ppm], check=True)
        w, h, px = read_ppm(ppm)
        # the background is neutral grey, the drop tan (red well above blue):
        # its top is the first row with a tan pixel in the middle third
        top = next((y for y in range(h) for x in range(w // 3, 2 * w // 3)
                    if px[y * w + x][0] - px[y * w + x][2] > 0.15), h)
        rows.append(top)
    check(rows == sorted(rows) and rows[0] < rows[-1],
          "the drop's top row along the sweep: %s (expected moving down)" % rows)

# ---- the same bytes: again, and at 2 threads
r = run(BT, "batch", sweep("again"), "--threads", "2")
check(r.returncode == 0, "the rerun at 2 threads: %s" % r.stderr[-2000:])
diff = same_bytes(ref, os.path.join(WORK, "again"), names) if files(os.path.join(WORK, "again")) \
    else names
check(not diff, "Cycles CPU at 1 and 2 threads, fixed seed: bytes differ in %s" % diff)

# ---- resume: nothing to do; another sample count re-renders
r = run(BT, "batch", sweep("ref"))
check(r.returncode == 0 and "0 done, 4 skipped" in r.stderr, "the rerun: %s" % r.stderr[-500:])
img16 = dict(IMG, samples=16)
r = run(BT, "batch", sweep("ref", img16))
check(r.returncode == 0 and "4 done, 0 skipped" in r.stderr,
      "samples 8 -> 16 re-renders every task: %s" % r.stderr[-500:])
r = run(BT, "batch", sweep("ref"))  # back to the reference images
check("4 done" in r.stderr, "samples back to 8: %s" % r.stderr[-500:])


# ---- a worker killed mid-render fails only its task
def children(pid):
    try:
        with open("/proc/%d/task/%d/children" % (pid, pid)) as f:
            return [int(c) for c in f.read().split()]
    except OSError:
        return []


crash = os.path.join(WORK, "crash")
slow = dict(IMG, width=320, height=240, samples=64)
p = subprocess.Popen([BT, "batch", sweep("crash", slow), "--log-json"], stdout=subprocess.PIPE,
                     stderr=subprocess.PIPE, text=True, env=ENV)
killed = None
lines = []
for line in p.stdout:
    lines.append(line)
    e = json.loads(line)
    if e["event"] == "task_start" and e["task"] == 1 and killed is None:
        time.sleep(0.3)  # into the render
        kids = children(p.pid)
        if kids:
            killed = kids[0]
            os.kill(killed, signal.SIGKILL)
err = p.stderr.read()
p.wait()
ends = {e["task"]: e for e in map(json.loads, lines) if e["event"] == "task_end"}
prog = [e["fraction"] for e in map(json.loads, lines) if e["event"] == "progress" and e["task"] == 0]
print("progress events of task 0: %s" % prog)
check(len(prog) >= 3 and prog == sorted(prog) and 0 < prog[0] and prog[-1] <= 1,
      "task 0's progress events (a 320x240 render at 64 samples): %s" % prog)
check(killed is not None, "no Blender worker to kill (children of blendtool)")
check(p.returncode == 1, "a killed worker: exit %s (expected 1): %s" % (p.returncode, err[-1500:]))
check(ends.get(1, {}).get("status") == "failed" and "died" in ends[1].get("error", ""),
      "task 1 failed saying the worker died: %s" % ends.get(1))
check(all(ends.get(i, {}).get("status") == "done" for i in (0, 2, 3)),
      "the other tasks done: %s" % {i: ends.get(i, {}).get("status") for i in range(4)})
check("drop_0001.png" not in files(crash) and not os.path.exists(
      os.path.join(crash, ".libblend-manifest", "drop_0001.json")),
      "the killed task left an image or a manifest: %s" % files(crash))
r = run(BT, "batch", sweep("crash", slow), "--log-json")
redone = [e["task"] for e in events(r.stdout) if e["event"] == "task_end" and e["status"] == "done"]
check(r.returncode == 0 and redone == [1], "the rerun redid %s (expected [1]): %s" %
      (redone, r.stderr[-500:]))
whole = os.path.join(WORK, "whole")
r = run(BT, "batch", sweep("whole", slow))
check(not same_bytes(crash, whole, names) if files(crash) == files(whole) else False,
      "after the crash and the rerun, the images equal an uninterrupted run's")
left = [f for f in os.listdir(WORK) if f.startswith("blendtool-")]
check(not left, "temporary folders left in TMPDIR: %s" % left)

# a worker that dies while idle (blendtool held still right after task 0's
# image, the worker killed, blendtool let go): the next request meets a
# closed pipe; that task fails, blendtool goes on with a new worker
idle = os.path.join(WORK, "idle")
p = subprocess.Popen([BT, "batch", sweep("idle"), "--log-json"], stdout=subprocess.PIPE,
                     stderr=subprocess.PIPE, text=True, env=ENV)
lines, idle_killed = [], None
for line in p.stdout:
    lines.append(line)
    e = json.loads(line)
    if e["event"] == "output" and e["task"] == 0 and idle_killed is None:
        os.kill(p.pid, signal.SIGSTOP)
        kids = children(p.pid)
        if kids:
            idle_killed = kids[0]
            os.kill(idle_killed, signal.SIGKILL)
            time.sleep(0.5)
        os.kill(p.pid, signal.SIGCONT)
err = p.stderr.read()
p.wait()
ends = {e["task"]: e for e in map(json.loads, lines) if e["event"] == "task_end"}
check(idle_killed is not None and p.returncode == 1,
      "an idle worker killed: blendtool exit %s (expected 1, not killed by SIGPIPE): %s" %
      (p.returncode, err[-800:]))
check(ends.get(1, {}).get("status") == "failed" and "died" in ends[1].get("error", "") and
      all(ends.get(i, {}).get("status") == "done" for i in (0, 2, 3)),
      "an idle worker killed: task 1 fails, the others are done: %s" %
      {i: ends.get(i, {}).get("status") for i in range(4)})

# ---- two shards at once, and --task through GNU parallel
sh = sweep("shards")
ps = [subprocess.Popen([BT, "batch", sh, "--shard", "%d/2" % i], stdout=subprocess.DEVNULL,
                       stderr=subprocess.PIPE, text=True, env=ENV) for i in range(2)]
outs = [q.communicate()[1] for q in ps]
check(all(q.returncode == 0 for q in ps), "two shards: %s" % outs)
shards = os.path.join(WORK, "shards")
check(files(shards) == names and not same_bytes(ref, shards, names),
      "two shards give the reference bytes: %s" % files(shards))
pj = sweep("parallel")
listing = run(BT, "batch", pj, "--list").stdout
ids = [line.split("\t")[0] for line in listing.splitlines()]
r = subprocess.run(["parallel", "-j", "2", BT, "batch", pj, "--task", "{}", ":::"] + ids,
                   capture_output=True, text=True, env=ENV)
par = os.path.join(WORK, "parallel")
check(r.returncode == 0 and files(par) == names and not same_bytes(ref, par, names),
      "GNU parallel over --task: %s %s" % (files(par), r.stderr[-800:]))

# ---- motion blur: a sphere moving 0.5 units a frame along x
SPHERE = {"format": "libblend-scene", "version": 1, "convention": "zero",
          "bounds": {"min": [-1.6, -0.6, -0.6], "max": [1.6, 0.6, 0.6]},
          "root": {"type": "sphere", "center": [0, 0, 0], "radius": 0.5},
          "render": {"camera": {"location": [0, -8, 0], "look_at": [0, 0, 0], "angle": 40},
                     "floor": False, "background": [0.5, 0.5, 0.5]}}
sphere = os.path.join(WORK, "sphere.json")
with open(sphere, "w") as f:
    json.dump(SPHERE, f)
FRAMES = {"first": 1, "last": 5, "fps": 24,
          "animate": [{"path": "root.center[0]", "keys": [[1, -1.0], [5, 1.0]]}]}
MB = {"format": "png", "width": 320, "height": 240, "renderer": "blender", "samples": 32,
      "mesh": 128, "alpha": True}


def alpha_rows(png):
    """the alpha channel's three middle rows (through the sphere's centre)"""
    ppm = png + ".a.ppm"
    subprocess.run(["oiiotool", png, "--ch", "A,A,A", "-o", ppm], check=True)
    w, h, px = read_ppm(ppm)
    return [[px[y * w + x][0] for x in range(w)] for y in (h // 2 - 1, h // 2, h // 2 + 1)]


def width_at(row, a):
    """the distance between the first and the last crossing of coverage a,
    interpolated between pixels"""
    xs = [i for i, v in enumerate(row) if v >= a]
    if not xs or xs[0] == 0 or xs[-1] == len(row) - 1:
        return float("nan")
    lo, hi = xs[0], xs[-1]
    left = lo - (row[lo] - a) / (row[lo] - row[lo - 1])
    right = hi + (row[hi] - a) / (row[hi] - row[hi + 1])
    return right - left


def ramp(rows):
    """A row of a shape that moves by d pixels during the shutter has coverage
    ramps d pixels long at both ends (a trapezoid): its width at coverage
    1/4 minus its width at 3/4 is d (plus the pixel filter's share, which a
    still image shows alone). Also the width at 1/2: the shape's own."""
    d = [width_at(r, 0.25) - width_at(r, 0.75) for r in rows]
    return sum(d) / len(d), sum(width_at(r, 0.5) for r in rows) / len(rows)


results = {}
for label, img in (("still", MB), ("blurred", dict(MB, motion_blur=1.0))):
    out = os.path.join(WORK, "mb-" + label)
    r = run(BT, "batch", job("move", out, {"image": img}, scene=sphere, frames=FRAMES),
            "--frames", "3")
    check(r.returncode == 0, "motion blur job (%s): %s" % (label, r.stderr[-1500:]))
    if r.returncode == 0:
        results[label] = ramp(alpha_rows(os.path.join(out, "move_0003.png")))
if len(results) == 2:
    (s_ramp, s_w), (b_ramp, b_w) = results["still"], results["blurred"]
    px_per_unit = s_w / 1.0  # the still sphere's width at half coverage: 1 unit
    blur = (b_ramp - s_ramp) / px_per_unit
    print("motion blur: sphere %.1f px wide (blurred %.1f px at half coverage); coverage ramps "
          "%.1f px still, %.1f px blurred: blur %.3f units (expected 0.5 = 0.5 units/frame x "
          "shutter 1 frame)" % (s_w, b_w, s_ramp, b_ramp, blur))
    check(abs(b_w - s_w) < 0.03 * s_w, "the blurred sphere's width at half coverage %.1f px, "
          "the still one's %.1f px" % (b_w, s_w))
    check(abs(blur - 0.5) < 0.03, "blur length %.3f units, expected 0.5 (6 %%)" % blur)
    check(s_ramp < 3.0, "without motion_blur the edges ramp over %.1f px (the pixel filter "
          "alone: about 1-2)" % s_ramp)

# ---- sweeps and frames together: 2 radii x 2 frames, names, sheet, metadata
both = os.path.join(WORK, "both")
r = run(BT, "batch", job("both", both, {"image": dict(MB, samples=4, mesh=48, width=120,
                                                        height=90, motion_blur=0.5),
                                        "contact_sheet": SHEET},
                         scene=sphere, sweep=[{"path": "root.radius", "values": [0.3, 0.45]}],
                         frames=dict(FRAMES, first=2, last=3)))
want = ["both_t%d_%04d.png" % (t, f) for t in (0, 1) for f in (2, 3)]
check(r.returncode == 0 and files(both) == sorted(want + ["both_sheet.png"]),
      "a sweep with frames: %s %s" % (files(both), r.stderr[-800:]))
if files(both):
    info = subprocess.run(["oiiotool", "--info", "-v", os.path.join(both, want[3])],
                          capture_output=True, text=True).stdout
    check("motion_blur 0.5" in info and "radius=0.45" in info and
          re.search(r"center\[0\]=0\"", info),
          "a sweep with frames: the image's metadata: %s" % info)

# ---- refused: no camera, no Blender, a POV-Ray key
nocam = dict(SPHERE)
nocam.pop("render")
ncp = os.path.join(WORK, "nocam.json")
with open(ncp, "w") as f:
    json.dump(nocam, f)
r = run(BT, "batch", job("nocam", os.path.join(WORK, "nocam"), {"image": IMG}, scene=ncp))
check(r.returncode == 1 and "no render.camera" in r.stderr and "allowed" in r.stderr,
      "a scene without a camera: exit %d: %s" % (r.returncode, r.stderr[-800:]))
r = run(BT, "batch", sweep("nob"), "--blender", os.path.join(WORK, "no-such-blender"))
check(r.returncode == 1 and "--version" in r.stderr and "--blender PATH" in r.stderr
      and not os.path.exists(os.path.join(WORK, "nob")),
      "a Blender that cannot run: exit %d: %s" % (r.returncode, r.stderr[-800:]))
r = run(BT, "batch", sweep("bad", dict(IMG, quality=9)))
check(r.returncode == 2 and "$.outputs.image.quality" in r.stderr and "povray" in r.stderr,
      "quality with renderer blender: exit %d: %s" % (r.returncode, r.stderr[-500:]))

# ---- EEVEE: Blender 3.4 renders it headless here; Blender 4.3 in the root
# has no OpenGL (no libEGL): the task fails saying what EEVEE needs
eimg = dict(IMG, engine="eevee")
r = run(BT, "batch", sweep("eevee", eimg), "--task", "2")
eout = os.path.join(WORK, "eevee")
check(r.returncode == 0 and files(eout) == [names[2]], "EEVEE on 3.4: %s" % r.stderr[-800:])
if files(eout):
    info = subprocess.run(["oiiotool", "--info", "-v", os.path.join(eout, names[2])],
                          capture_output=True, text=True).stdout
    check("Blender 3.4.1 eevee samples 8" in info, "EEVEE's metadata: %s" % info)
    check(same_bytes(ref, eout, [names[2]]), "EEVEE's image is not Cycles' image")
r = run(BT, "batch", sweep("eevee4", eimg), "--task", "2", "--blender",
        os.path.join(SRC, "tests", "blender", "blender4_worker.sh"))
check(r.returncode == 1 and "EEVEE needs OpenGL" in r.stderr and "libEGL" in r.stderr,
      "EEVEE on 4.3 without OpenGL: exit %d: %s" % (r.returncode, r.stderr[-800:]))

# ---- an installed blendtool finds its add-on (share/libblend/blender_addon)
inst = os.path.join(WORK, "inst")
r = subprocess.run(["cmake", "--install", os.path.dirname(os.path.dirname(BT)), "--prefix", inst],
                   capture_output=True, text=True)
check(r.returncode == 0, "cmake --install: %s" % r.stderr[-500:])
env_inst = {k: v for k, v in ENV.items() if k != "LIBBLEND_BLENDER_ADDON"}
r = subprocess.run([os.path.join(inst, "bin", "blendtool"), "batch", sweep("installed"), "--task",
                    "1"], capture_output=True, text=True, env=env_inst)
check(r.returncode == 0 and files(os.path.join(WORK, "installed")) == [names[1]] and
      not same_bytes(ref, os.path.join(WORK, "installed"), [names[1]]),
      "the installed blendtool renders with its installed add-on, the same bytes: %s" %
      r.stderr[-800:])

# ---- Blender 4.3 (the Debian 13 root) renders the same job
b4 = os.path.join(SRC, "tests", "blender", "blender4_worker.sh")
r = run(BT, "batch", sweep("b43"), "--blender", b4)
out4 = os.path.join(WORK, "b43")
check(r.returncode == 0 and files(out4) == names + ["drop_sheet.png"],
      "Blender 4.3: exit %d, %s: %s" % (r.returncode, files(out4), r.stderr[-1500:]))
if files(out4):
    info = subprocess.run(["oiiotool", "--info", "-v", os.path.join(out4, names[0])],
                          capture_output=True, text=True).stdout
    check(re.search(r'libblend:render: "160x120 Blender 4\.3\.\d+ cycles', info),
          "Blender 4.3's image metadata: %s" % info)
    r1 = run(BT, "batch", sweep("b43-2"), "--blender", b4, "--threads", "2")
    diff = same_bytes(out4, os.path.join(WORK, "b43-2"), names) if r1.returncode == 0 else names
    check(not diff, "Blender 4.3, Cycles CPU at 1 and 2 threads: bytes differ in %s %s" %
          (diff, r1.stderr[-500:]))
    r2 = run(BT, "batch", sweep("b43"), "--blender", b4)
    check("4 skipped" in r2.stderr, "Blender 4.3 rerun skips: %s" % r2.stderr[-300:])
    r3 = run(BT, "batch", sweep("b43"))
    check("4 done" in r3.stderr, "Blender 3.4 after 4.3 re-renders (the version is in the "
          "manifest): %s" % r3.stderr[-300:])

finish("test_farm", "the Blender renderer: sweep, determinism, resume, crash, shards, "
       "parallel, motion blur, refusals, Blender 4.3")
