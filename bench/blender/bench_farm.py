#!/usr/bin/python3
"""The Blender renderer of blendtool batch (docs/batch.md, "Rendering with
Blender"), against the ways a farm would do without it, in one run:
  - `blendtool batch` with outputs.image.renderer "blender": one worker
    Blender takes the 64 tasks one after another;
  - the baseline: a shell-style loop of one `blender -b --factory-startup`
    per task, each rendering the same image through the same add-on code
    (bench/blender/render_one.py: one request to farm_worker.render);
  - the same job rendered by POV-Ray (the default renderer) from the same
    mesh (`mesh` 128: the isosurface of 64 spheres takes minutes a frame),
    for the ratio.
The job: 64 tasks sweeping the blend range r of the S2 lattice (64
spheres, scenes/bench-s2-64-spheres.json), 320 x 240, Cycles at 16
samples, mesh 128, Blender's threads 2 (all of this machine's cores).
Reports wall times, the worker model's per-task overhead over Blender's
render itself (the `blender` events' render_seconds; bar: at most 0.3 s),
the loop's, and the POV-Ray ratio.

usage: bench_farm.py BLENDTOOL SOURCE_DIR WORK_DIR [TASKS]
"""
import json
import os
import shutil
import subprocess
import sys
import time

BT, SRC, WORK = (os.path.abspath(a) for a in sys.argv[1:4])
N = int(sys.argv[4]) if len(sys.argv) > 4 else 64
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
SCENE = os.path.join(SRC, "scenes", "bench-s2-64-spheres.json")
values = [0.05 + 0.25 * i / (N - 1) for i in range(N)]
IMG = {"width": 320, "height": 240, "renderer": "blender", "samples": 16, "mesh": 128,
       "threads": 2}
ADDON = os.path.join(os.path.dirname(os.path.dirname(BT)), "blender_addon")
ENV = dict(os.environ, LIBBLEND_BLENDER_ADDON=ADDON, TMPDIR=WORK)


def job(name, img):
    d = os.path.join(WORK, name)
    os.makedirs(d)
    p = os.path.join(d, "s2.json")
    json.dump({"format": "libblend-job", "version": 1, "name": "s2", "scene": SCENE,
               "sweep": [{"path": "root.r", "values": values}],
               "outputs": {"image": img}, "output_dir": "out"}, open(p, "w"))
    return p


# the worker model
t0 = time.monotonic()
r = subprocess.run([BT, "batch", job("worker", IMG), "--log-json"], capture_output=True,
                   text=True, env=ENV)
worker = time.monotonic() - t0
assert r.returncode == 0, r.stderr
ev = [json.loads(line) for line in r.stdout.splitlines() if line.startswith("{")]
render = [e["render_seconds"] for e in ev if e["event"] == "blender"]
assert len(render) == N, len(render)

# the loop: one Blender per task, the same request
base = json.load(open(SCENE))
one = os.path.join(SRC, "bench", "blender", "render_one.py")
loop_render = []
t0 = time.monotonic()
for i, v in enumerate(values):
    sc = dict(base, root=dict(base["root"], r=v))
    sp = os.path.join(WORK, "loop_%04d.json" % i)
    json.dump(sc, open(sp, "w"))
    req = {"scene": sp, "name": "s2", "out": os.path.join(WORK, "loop_%04d.png" % i),
           "width": 320, "height": 240, "engine": "cycles", "samples": 16, "seed": 0,
           "threads": 2, "resolution": 128, "bits16": True, "alpha": True,
           "transparent": False, "fps": 24, "shutter": 0}
    rp = os.path.join(WORK, "loop_%04d.req" % i)
    json.dump(req, open(rp, "w"))
    q = subprocess.run(["blender", "-b", "--factory-startup", "--python-exit-code", "1",
                        "--python", one, "--", ADDON, rp], capture_output=True, text=True)
    assert q.returncode == 0, q.stdout[-2000:] + q.stderr[-2000:]
    loop_render.append(json.load(open(rp + ".reply"))["render_seconds"])
loop = time.monotonic() - t0

# POV-Ray, the same sweep and size
t0 = time.monotonic()
r = subprocess.run([BT, "batch", job("povray", {"width": 320, "height": 240, "mesh": 128}),
                    "--threads", "2"],
                   capture_output=True, text=True, env=ENV)
pov = time.monotonic() - t0
assert r.returncode == 0, r.stderr

mean_r = sum(render) / N
mean_lr = sum(loop_render) / N
print("%d tasks, 320x240, Cycles 16 samples, S2 lattice sweep of r (%s)" %
      (N, time.strftime("%Y-%m-%d")))
print("| run | wall s | per task | Blender's render per task |")
print("|---|---|---|---|")
print("| one `blender -b` per task (the baseline) | %.1f | %.2f s | %.2f s |" %
      (loop, loop / N, mean_lr))
print("| `blendtool batch`, one worker Blender | %.1f | %.2f s | %.2f s |" %
      (worker, worker / N, mean_r))
print("| `blendtool batch`, POV-Ray (quality 9, the same mesh) | %.1f | %.2f s | |" % (pov, pov / N))
print("worker overhead per task over the render: %.3f s (bar: at most 0.3 s); the loop's: %.3f s"
      % (worker / N - mean_r, loop / N - mean_lr))
print("worker / loop: %.2fx faster; Blender (worker) / POV-Ray wall: %.2f" %
      (loop / worker, worker / pov))
