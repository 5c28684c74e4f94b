#!/usr/bin/python3
"""Throughput of blendtool batch (docs/batch.md, "Speed"): a 64-task sweep,
each task a mesh (64 cells) and a 160 x 120 render, run
  - as a plain shell loop of `blendtool mesh --set` and `blendtool render --set`
    (the baseline, one process pair per task),
  - as `blendtool batch` in one process,
  - as two shards side by side (`--shard 0/2`, `--shard 1/2`) on the 2 cores,
  - through Slurm (`--submit --array-size 2`, the single-node cluster of
    scripts/slurm-cluster.sh),
in one run. Reports wall times, the batch overhead per task against the
loop, Slurm's against the local batch, and the parallel efficiency (one
process's time over the two shards' time).

usage: bench_batch.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import json
import os
import shutil
import subprocess
import sys
import time

BT, SRC, WORK = (os.path.abspath(a) for a in sys.argv[1:4])
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
N = 64
SCENE = os.path.join(SRC, "scenes", "bernhardt-compare-local.json")
PATH = "root.args[0].center[0]"
values = [-0.8 + 0.5 * i / (N - 1) for i in range(N)]
JOB = {"format": "libblend-job", "version": 1, "name": "b", "scene": SCENE,
       "sweep": [{"path": PATH, "values": values}],
       "outputs": {"mesh": {"resolution": 64}, "image": {"width": 160, "height": 120}}}


def job(name):
    d = os.path.join(WORK, name)
    os.makedirs(d)
    p = os.path.join(d, "b.json")
    json.dump(JOB, open(p, "w"))
    return p


def timed(fn):
    t0 = time.time()
    fn()
    return time.time() - t0


def loop():
    d = os.path.join(WORK, "loop")
    os.makedirs(d)
    script = "set -e\n" + "".join(
        "'%s' mesh '%s' -o '%s/b_%04d.ply' --resolution 64 --threads 1 --quiet --set '%s=%r'\n"
        "'%s' render '%s' -o '%s/b_%04d.png' --width 160 --height 120 --threads 1 --set '%s=%r' "
        "2>/dev/null\n" % (BT, SCENE, d, i, PATH, v, BT, SCENE, d, i, PATH, v)
        for i, v in enumerate(values))
    subprocess.run(["bash", "-c", script], check=True)


def batch():
    subprocess.run([BT, "batch", job("batch"), "--threads", "1"], check=True,
                   stderr=subprocess.DEVNULL)


def shards():
    p = job("shards")
    ps = [subprocess.Popen([BT, "batch", p, "--shard", "%d/2" % i, "--threads", "1"],
                           stderr=subprocess.DEVNULL) for i in range(2)]
    for q in ps:
        if q.wait():
            raise SystemExit("a shard failed")


def slurm():
    subprocess.run([BT, "batch", job("slurm"), "--submit", "--array-size", "2"], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


cluster = os.path.join(WORK, "cluster")
subprocess.run(["bash", os.path.join(SRC, "scripts", "slurm-cluster.sh"), "start", cluster],
               check=True)
os.environ["SLURM_CONF"] = os.path.join(cluster, "slurm.conf")
try:
    t_loop = timed(loop)
    t_batch = timed(batch)
    t_shards = timed(shards)
    t_slurm = timed(slurm)
finally:
    subprocess.run(["bash", os.path.join(SRC, "scripts", "slurm-cluster.sh"), "stop", cluster])
print("| run | wall s | per task ms |")
print("|---|---|---|")
for name, t in (("shell loop of blendtool mesh + render", t_loop), ("blendtool batch, 1 process", t_batch),
                ("2 shards side by side", t_shards), ("Slurm, 2 array tasks", t_slurm)):
    print("| %s | %.2f | %.1f |" % (name, t, 1000 * t / N))
print()
print("batch overhead per task against the loop: %.1f ms (bar: under 50 ms)" % (1000 * (t_batch - t_loop) / N))
print("Slurm overhead per task against 2 local shards: %.1f ms (bar: under 1000 ms)" %
      (1000 * (t_slurm - t_shards) / N))
print("parallel efficiency, 1 process / 2 shards: %.2fx (bar: at least 1.8x)" % (t_batch / t_shards))
