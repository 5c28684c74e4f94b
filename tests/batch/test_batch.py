#!/usr/bin/python3
"""blendtool batch, for real: job files, task lists, outputs through POV-Ray
and OpenImageIO, resume after SIGKILL, shards, frames, overrides, bad job
files, GNU parallel, blendtool compare.

usage: test_batch.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import glob
import hashlib
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time

import jsonschema

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from batchlib import bt, check, digest, fail, finish, setup  # noqa: E402

BT, SRC, WORK = setup()
# render folders in a TMPDIR of this test's own: the SIGKILL trials check that
# none is left behind, which a shared /tmp cannot show while other tests (run
# in parallel by ctest) render
TMP = os.path.join(WORK, "tmp")
os.makedirs(TMP)
os.environ["TMPDIR"] = TMP
SCHEMA = json.load(open(os.path.join(SRC, "docs", "libblend-job.schema.json")))


def write_job(path, job):
    with open(path, "w") as f:
        json.dump(job, f, indent=1)
    return path


def events(text):
    return [json.loads(l) for l in text.splitlines() if l.startswith("{")]


def why(r):
    """what a run said about its failed tasks, and the end of its stderr: a
    status check that fails shows the cause, not only the statuses"""
    errs = ["%s: %s" % (e["name"], e.get("error", "")) for e in events(r.stdout)
            if e["event"] == "task_end" and e["status"] == "failed"]
    return "\n  exit %d; failed tasks: %s\n  stderr: %s" % (r.returncode, errs or "none",
                                                           r.stderr[-1500:])


DROP = os.path.join(SRC, "scenes", "bernhardt-compare-local.json")
BASE = {
    "format": "libblend-job", "version": 1, "name": "cmp",
    "scene": DROP,
    "sweep": [{"path": "root.args[0].center[0]", "range": {"from": -0.75, "to": -0.35, "count": 3}},
              {"path": "root.alpha", "values": [[0, 0], [0.1, 0.1]]}],
    "outputs": {"mesh": {"format": "ply", "resolution": 40},
                "pov": {"width": 160, "height": 120},
                "image": {"format": "png", "width": 96, "height": 72},
                "contact_sheet": {"columns": 3, "cell_width": 96, "cell_height": 72}},
}

# ---- the schema accepts the jobs this test runs
for j in (BASE,):
    try:
        jsonschema.validate(j, SCHEMA)
    except jsonschema.ValidationError as e:
        fail("schema rejects a good job: %s" % e.message)

# ---- the shipped example jobs: valid, and their task lists expand
for p in sorted(glob.glob(os.path.join(SRC, "scenes", "jobs", "*.json"))):
    try:
        jsonschema.validate(json.load(open(p)), SCHEMA)
    except jsonschema.ValidationError as e:
        fail("%s: the schema rejects it: %s" % (p, e.message))
    r = bt("batch", p, "--list")
    check(r.returncode == 0 and len(r.stdout.splitlines()) >= 10, "%s --list: %s" % (p, r.stderr))

# ---- the task list: deterministic, independent of the folder it runs from
d1 = os.path.join(WORK, "a")
os.makedirs(d1)
job1 = write_job(os.path.join(d1, "cmp.json"), BASE)
l1 = bt("batch", job1, "--list")
l2 = bt("batch", "cmp.json", "--list", cwd=d1)
check(l1.returncode == 0 and l1.stdout == l2.stdout and len(l1.stdout.splitlines()) == 6,
      "--list: 6 tasks, the same from any folder:\n%s%s" % (l1.stdout, l1.stderr))
rows = [r.split("\t") for r in l1.stdout.splitlines()]
check([r[0] for r in rows] == [str(i) for i in range(6)], "task ids 0..5 in order")
check(rows[0][1] == "cmp_0000" and rows[5][1] == "cmp_0005", "names follow the pattern: %s" % rows)
check(rows[0][3] == "cmp_0000.ply,cmp_0000.pov,cmp_0000.png", "outputs per task: %s" % rows[0][3])
check(len(set(r[2] for r in rows)) == 6, "six distinct scene hashes")
check("center[0]=-0.75 alpha=[0,0]" == rows[0][4] and "center[0]=-0.35 alpha=[0.1,0.1]" == rows[5][4],
      "labels: first axis slowest: %s / %s" % (rows[0][4], rows[5][4]))

# ---- a run: every output, the log, the manifests, the contact sheet
r = bt("batch", job1, "--log-json")
ev = events(r.stdout)
check(r.returncode == 0, "batch run" + why(r))
out1 = os.path.join(d1, "out")
names = sorted(os.listdir(out1))
check(len([n for n in names if n.endswith(".png") and "sheet" not in n]) == 6 and
      "cmp_sheet.png" in names and len([n for n in names if n.endswith(".ply")]) == 6,
      "outputs: %s" % names)
kinds = [e["event"] for e in ev]
check(kinds[0] == "job" and kinds[-1] == "job_end" and kinds.count("task_end") == 6 and
      kinds.count("output") == 18 and "contact_sheet" in kinds, "log events: %s" % kinds)
ends = [e for e in ev if e["event"] == "task_end"]
check(all(e["status"] == "done" and e["seconds"] > 0 and e["peak_rss_kb"] > 0 for e in ends),
      "task_end fields: %s" % ends[:1])
check(sorted(os.listdir(os.path.join(out1, ".libblend-manifest"))) ==
      ["cmp_%04d.json" % i for i in range(6)] + ["tasks.lock"],
      "one manifest per task, and the tasks' lock file")
m = json.load(open(os.path.join(out1, ".libblend-manifest", "cmp_0003.json")))
ident = json.loads(m["identity"])
check(ident["scene_hash"] == rows[3][2] and ident["libblend"] and len(m["outputs"]) == 3,
      "manifest: %s" % m)
# images: OpenImageIO's metadata, no date, the sheet's grid
info = subprocess.run(["iinfo", "-v", os.path.join(out1, "cmp_0003.png")], capture_output=True,
                      text=True).stdout
check("libblend:scene_hash: \"%s\"" % rows[3][2] in info and re.search(r"96 x +72", info) and
      "DateTime" not in info and "libblend:task: \"cmp_0003\"" in info, "image metadata:\n" + info)
sheet = subprocess.run(["iinfo", os.path.join(out1, "cmp_sheet.png")], capture_output=True,
                       text=True).stdout
check(re.search(r"304 x +192", sheet), "contact sheet 3 x 2 cells of 96 x 72 (+ labels, padding): " + sheet)

# ---- a second run skips everything; a fresh run elsewhere gives the same bytes
r = bt("batch", job1, "--log-json")
check(r.returncode == 0 and all(e["status"] == "skipped" for e in events(r.stdout)
                                if e["event"] == "task_end"), "rerun skips complete tasks" + why(r))
ref = digest(out1)
d2 = os.path.join(WORK, "b")
os.makedirs(d2)
job2 = write_job(os.path.join(d2, "cmp.json"), BASE)
time.sleep(1.1)  # a different second: a time stamp would show
r = bt("batch", job2)
check(r.returncode == 0 and digest(os.path.join(d2, "out")) == ref,
      "the same job elsewhere, later: byte-identical outputs and manifests" + why(r))

# ---- a changed or damaged output is redone, the rest skipped
victim = os.path.join(out1, "cmp_0002.png")
with open(victim, "r+b") as f:
    f.seek(100)
    f.write(b"\0\0\0\0")
os.remove(os.path.join(out1, "cmp_0004.ply"))
r = bt("batch", job1, "--log-json")
st = {e["name"]: e["status"] for e in events(r.stdout) if e["event"] == "task_end"}
check(st == {"cmp_0000": "skipped", "cmp_0001": "skipped", "cmp_0002": "done",
             "cmp_0003": "skipped", "cmp_0004": "done", "cmp_0005": "skipped"},
      "damaged and missing outputs redo their task only: %s%s" % (st, why(r)))
check(digest(out1) == ref, "and the redone outputs are the same bytes")

# ---- shards and single tasks: together the same files as the whole run
d3 = os.path.join(WORK, "c")
os.makedirs(d3)
job3 = write_job(os.path.join(d3, "cmp.json"), BASE)
seen = []
for i in range(4):
    r = bt("batch", job3, "--shard", "%d/4" % i, "--log-json")
    seen += [e["task"] for e in events(r.stdout) if e["event"] == "task_end"]
    check(r.returncode == 0, "shard %d/4%s" % (i, why(r)))
check(seen == list(range(6)), "shards 0..3 of 4 cover tasks 0..5 once, in order: %s" % seen)
r = bt("batch", job3, "--sheet")
check(r.returncode == 0 and digest(os.path.join(d3, "out")) == ref,
      "shards + --sheet give the whole run's bytes")
r = bt("batch", job3, "--task", "4", "--log-json")
check([e["status"] for e in events(r.stdout) if e["event"] == "task_end"] == ["skipped"],
      "--task 4 alone: complete, skipped" + why(r))

# ---- frames, keyframes and interpolation; EXR and 16-bit PNG with alpha
anim = {
    "format": "libblend-job", "version": 1, "name": "anim", "scene": DROP,
    "frames": {"first": 1, "last": 9, "animate": [
        {"path": "root.args[0].center[0]", "keys": [[1, -0.8], [5, -0.4], [9, -0.6]]},
        {"path": "root.args[1].center[1]", "keys": [[1, 0.0], [9, 0.4]], "interpolation": "smooth"},
        {"path": "root.args[0].radius", "keys": [[1, 0.5], [4, 0.55]], "interpolation": "step"}]},
    "outputs": {"image": {"format": "exr", "pixel": "half", "alpha": True, "width": 64, "height": 48}},
    "pattern": "shot_###",
}
jsonschema.validate(anim, SCHEMA)
d4 = os.path.join(WORK, "d")
os.makedirs(d4)
job4 = write_job(os.path.join(d4, "anim.json"), anim)
l = bt("batch", job4, "--list", "--frames", "3-6")
rows = [r.split("\t") for r in l.stdout.splitlines()]
check([r[1] for r in rows] == ["shot_003", "shot_004", "shot_005", "shot_006"],
      "--frames 3-6 and ### padding: %s %s" % ([r[1] for r in rows], l.stderr))


def expect(frame):
    x = -0.8 + 0.4 * (frame - 1) / 4 if frame <= 5 else -0.4 - 0.2 * (frame - 5) / 4
    u = (frame - 1) / 8
    y = 0.4 * u * u * (3 - 2 * u)
    rad = 0.5 if frame < 4 else 0.55
    return x, y, rad


for r in rows:
    fr = int(r[1][-3:])
    got = dict(kv.split("=") for kv in r[4].split())
    x, y, rad = expect(fr)
    check(abs(float(got["center[0]"]) - x) < 1e-3 and abs(float(got["center[1]"]) - y) < 1e-3
          and abs(float(got["radius"]) - rad) < 1e-9,
          "frame %d: keys linear / smooth / step: %s, expected %s" % (fr, got, (x, y, rad)))
r = bt("batch", job4, "--frames", "2-3")
info = subprocess.run(["iinfo", "-v", os.path.join(d4, "out", "shot_002.exr")],
                      capture_output=True, text=True).stdout
check(r.returncode == 0 and "4 channel, half openexr" in info and "R, G, B, A" in info,
      "EXR half with alpha: %s %s" % (info[:200], r.stderr[-300:]))
check(not os.path.exists(os.path.join(d4, "out", "shot_004.exr")), "--frames renders only those")
d4b = os.path.join(WORK, "d2")
os.makedirs(d4b)
time.sleep(1.1)  # OpenImageIO's EXR writer stamps the time unless told not to
r = bt("batch", write_job(os.path.join(d4b, "anim.json"), anim), "--frames", "2-3")
check(r.returncode == 0 and digest(os.path.join(d4b, "out")) == digest(os.path.join(d4, "out")),
      "EXR outputs are the same bytes a second later")
anim16 = dict(anim, outputs={"image": {"format": "png", "bits": 16, "alpha": True, "width": 64, "height": 48}},
              name="anim16")
job5 = write_job(os.path.join(d4, "anim16.json"), anim16)
r = bt("batch", job5, "--frames", "2")
info = subprocess.run(["iinfo", os.path.join(d4, "out", "shot_002.png")], capture_output=True,
                      text=True).stdout
check(r.returncode == 0 and "4 channel, uint16 png" in info, "16-bit PNG with alpha: " + info)

# ---- --set on the single commands
sc = os.path.join(SRC, "scenes", "bernhardt-drop-06.json")
a = os.path.join(WORK, "set.ply")
r = bt("mesh", sc, "-o", a, "--resolution", "24", "--quiet", "--set", "root.args[0].radius=0.4")
check(r.returncode == 0 and os.path.exists(a), "mesh --set: %s" % r.stderr)
r = bt("mesh", sc, "-o", a + "2.ply", "--resolution", "24", "--quiet", "--set",
       "root.args[0].radius=-1")
check(r.returncode == 2 and "radius" in r.stderr and "--set root.args[0].radius" in r.stderr and
      "allowed" in r.stderr and not os.path.exists(a + "2.ply"),
      "an override making the scene invalid: the scene's message, the override named: " + r.stderr)
r = bt("pov", sc, "-o", a + ".pov", "--set", "root.args[7].radius=1")
check(r.returncode == 2 and "$.root.args has 2 elements" in r.stderr and
      not os.path.exists(a + ".pov"), "a path that does not exist is named: " + r.stderr)
r = bt("render", sc, "-o", a + ".png", "--set", "root.args[0].radius=oops")
check(r.returncode == 2 and "not one JSON value" in r.stderr, "a value that is not JSON: " + r.stderr)

# ---- bad job files: exit 2, the file, the place, what is allowed, nothing written
good = dict(BASE, output_dir="bad-out")
CASES = [
    ("not json", "{\"format\": ", "not valid JSON"),
    ("array", [], "$: expected an object"),
    ("format", dict(good, format="libblend-scene"), "$.format"),
    ("version", dict(good, version=2), "$.version"),
    ("unknown key", dict(good, extra=1), "unknown key \"extra\""),
    ("no scene", {k: v for k, v in good.items() if k != "scene"}, "\"scene\""),
    ("both scenes", dict(good, scenes=[DROP]), "one of \"scene\""),
    ("scene missing", dict(good, scene="nope.json"), "$.scene"),
    ("scene number", dict(good, scene=3), "$.scene"),
    ("scenes empty", dict({k: v for k, v in good.items() if k != "scene"}, scenes=[]), "$.scenes"),
    ("name slash", dict(good, name="a/b"), "$.name"),
    ("set not object", dict(good, set=[1]), "$.set"),
    ("set bad path", dict(good, set={"root args": 1}), "$.set"),
    ("sweep not list", dict(good, sweep={}), "$.sweep"),
    ("axis no path", dict(good, sweep=[{"values": [1]}]), "$.sweep[0]"),
    ("axis both", dict(good, sweep=[{"path": "root.alpha", "values": [1], "range": {}}]), "$.sweep[0]"),
    ("axis empty values", dict(good, sweep=[{"path": "root.alpha", "values": []}]), "$.sweep[0]"),
    ("range count", dict(good, sweep=[{"path": "a", "range": {"from": 0, "to": 1, "count": 0}}]), "count"),
    ("range key", dict(good, sweep=[{"path": "a", "range": {"from": 0, "to": 1, "n": 3}}]), "unknown key \"n\""),
    ("range from", dict(good, sweep=[{"path": "a", "range": {"from": "x", "to": 1, "count": 2}}]), "\"from\""),
    ("frames order", dict(good, frames={"first": 5, "last": 2}), "$.frames"),
    ("frames key", dict(good, frames={"first": 1, "last": 2, "rate": 24}), "unknown key \"rate\""),
    ("frames fps", dict(good, frames={"first": 1, "last": 2, "fps": 0}), "$.frames"),
    ("keys order", dict(good, frames={"first": 1, "last": 2, "animate": [
        {"path": "a", "keys": [[2, 0], [1, 1]]}]}), "increasing frames"),
    ("keys pair", dict(good, frames={"first": 1, "last": 2, "animate": [
        {"path": "a", "keys": [[1]]}]}), "keys[0]"),
    ("interp", dict(good, frames={"first": 1, "last": 2, "animate": [
        {"path": "a", "keys": [[1, 0]], "interpolation": "cubic"}]}), "\"interpolation\""),
    ("no outputs", {k: v for k, v in good.items() if k != "outputs"}, "$.outputs"),
    ("empty outputs", dict(good, outputs={}), "$.outputs"),
    ("mesh format", dict(good, outputs={"mesh": {"format": "fbx"}}), "$.outputs.mesh.format"),
    ("mesh resolution", dict(good, outputs={"mesh": {"resolution": 0}}), "resolution"),
    ("mesh features", dict(good, outputs={"mesh": {"features": "yes"}}), "$.outputs.mesh.features"),
    ("mesh simplify", dict(good, outputs={"mesh": {"simplify": 1.5}}), "$.outputs.mesh.simplify"),
    ("simplify type", dict(good, outputs={"mesh": {"simplify": "0.1"}}), "$.outputs.mesh.simplify"),
    ("merge_flat type", dict(good, outputs={"mesh": {"merge_flat": 1}}), "$.outputs.mesh.merge_flat"),
    ("image format", dict(good, outputs={"image": {"format": "jpg"}}), "$.outputs.image.format"),
    ("image bits", dict(good, outputs={"image": {"bits": 12}}), "bits"),
    ("exr bits", dict(good, outputs={"image": {"format": "exr", "bits": 16}}), "$.outputs.image.bits"),
    ("png pixel", dict(good, outputs={"image": {"pixel": "half"}}), "$.outputs.image.pixel"),
    ("alpha type", dict(good, outputs={"image": {"alpha": "yes"}}), "$.outputs.image.alpha"),
    ("image size", dict(good, outputs={"image": {"width": 0}}), "width"),
    ("sheet alone", dict(good, outputs={"mesh": {}, "contact_sheet": {}}), "needs \"image\""),
    ("pattern", dict(good, pattern="frame"), "$.pattern"),
    ("pattern slash", dict(good, pattern="a/####"), "$.pattern"),
    ("threads", dict(good, threads=-1), "threads"),
    ("too many", dict(good, sweep=[{"path": "a", "range": {"from": 0, "to": 1, "count": 100000}},
                                   {"path": "b", "values": [1, 2]}]), "at most 100000"),
]
bad_dir = os.path.join(WORK, "bad")
os.makedirs(bad_dir)
check(len(CASES) >= 30, "at least 30 bad job files")
schema_caught = 0
for name, doc, want in CASES:
    p = os.path.join(bad_dir, "job.json")
    with open(p, "w") as f:
        f.write(doc if isinstance(doc, str) else json.dumps(doc))
    for args in ((), ("--list",)):
        r = bt("batch", p, *args)
        ok = (r.returncode == 2 and p in r.stderr and want in r.stderr and
              ("allowed" in r.stderr or "one of" in r.stderr or "not valid JSON" in r.stderr))
        check(ok, "bad job %r %s: exit %d: %s" % (name, args, r.returncode, r.stderr.strip()))
    check(not os.path.exists(os.path.join(bad_dir, "bad-out")), "bad job %r wrote nothing" % name)
    if not isinstance(doc, str):
        try:
            jsonschema.validate(doc, SCHEMA)
        except jsonschema.ValidationError:
            schema_caught += 1
# the schema knows every case but those that need the files (a missing
# scene), the product of the axes, or comparisons (first <= last,
# increasing keys), and the text that is not JSON
check(schema_caught >= len(CASES) - 5, "the JSON Schema rejects %d of %d bad jobs" % (schema_caught, len(CASES)))
# a task whose sweep value makes its scene invalid: the job is refused before
# anything runs (exit 2, the task and the override named), nothing created
bad_value = dict(BASE, output_dir="partly", sweep=[{"path": "root.args[0].radius", "values": [0.5, -1, 0.45]}],
                 outputs={"mesh": {"resolution": 24}})
p = write_job(os.path.join(bad_dir, "partly.json"), bad_value)
for args in ((), ("--list",)):
    r = bt("batch", p, "--log-json", *args)
    check(r.returncode == 2 and "radius" in r.stderr and "--set root.args[0].radius=-1" in r.stderr,
          "an invalid task %s: exit 2 naming the override: %d %s" % (args, r.returncode, r.stderr))
    check(not os.path.exists(os.path.join(bad_dir, "partly")), "an invalid task %s: nothing created" % (args,))
# a task that fails while running (its output path is a folder) fails alone:
# the others run, the error is logged, the exit status is the failure's
good_value = dict(bad_value, sweep=[{"path": "root.args[0].radius", "values": [0.5, 0.4, 0.45]}])
p = write_job(os.path.join(bad_dir, "partly.json"), good_value)
os.makedirs(os.path.join(bad_dir, "partly", "cmp_0001.ply"))
r = bt("batch", p, "--log-json")
st = [e["status"] for e in events(r.stdout) if e["event"] == "task_end"]
err = [e.get("error", "") for e in events(r.stdout) if e["event"] == "task_end"]
check(r.returncode == 2 and st == ["done", "failed", "done"] and "cmp_0001.ply" in err[1],
      "one failing task: exit 2 (its output path cannot take a file), the others done, the error "
      "logged: %d %s %s" % (r.returncode, st, err))
r = bt("batch", p, "--fail-fast", "--log-json")
check(r.returncode == 2 and [e["status"] for e in events(r.stdout) if e["event"] == "task_end"] ==
      ["skipped", "failed"], "--fail-fast stops at the failure")

# ---- SIGKILL at random points: nothing corrupt, nothing complete redone
kjob = dict(BASE, outputs={"mesh": {"resolution": 40}, "image": {"format": "png", "width": 96, "height": 72}})
dk = os.path.join(WORK, "kill")
os.makedirs(dk)
jk = write_job(os.path.join(dk, "k.json"), kjob)
dref = os.path.join(WORK, "kill-ref")
os.makedirs(dref)
r = bt("batch", write_job(os.path.join(dref, "k.json"), kjob))
kref = digest(os.path.join(dref, "out"))
t0 = time.time()
r = bt("batch", write_job(os.path.join(dref, "k2.json"), dict(kjob, name="k2", output_dir="o2")))
full_time = time.time() - t0
rng = random.Random(13)
redone_complete = 0
killed = 0  # render folders the killed runs left (the next run removes them)
for trial in range(20):
    before = {n for n in os.listdir(os.path.join(dk, "out", ".libblend-manifest"))} \
        if os.path.isdir(os.path.join(dk, "out", ".libblend-manifest")) else set()
    p = subprocess.Popen([BT, "batch", jk], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(rng.uniform(0.0, full_time * 1.1))
    p.send_signal(signal.SIGKILL)
    p.wait()
    killed += len(glob.glob(os.path.join(TMP, "blendtool-render-*")))
    out = os.path.join(dk, "out")
    # every manifest that exists vouches for complete outputs
    for mf in glob.glob(os.path.join(out, ".libblend-manifest", "*.json")):
        m = json.load(open(mf))
        for o in m["outputs"]:
            check(os.path.exists(os.path.join(out, o["file"])), "trial %d: manifest without its output" % trial)
    vis = [n for n in os.listdir(out) if not n.startswith(".")] if os.path.isdir(out) else []
    for n in vis:  # a visible output is complete: the reference's bytes
        check(hashlib.sha256(open(os.path.join(out, n), "rb").read()).hexdigest() == kref.get(n),
              "trial %d: %s is not the complete output" % (trial, n))
    r = bt("batch", jk, "--log-json")
    st = {e["name"]: e["status"] for e in events(r.stdout) if e["event"] == "task_end"}
    for n in before:
        if st.get(n[:-5]) == "done":
            redone_complete += 1
    check(r.returncode == 0 and digest(out) == kref,
          "trial %d: the rerun completes the job%s" % (trial, why(r)))
    shutil.rmtree(out) if trial % 2 else None
check(redone_complete == 0, "a task complete before a kill was redone %d times" % redone_complete)
r = bt("render", DROP, "-o", os.path.join(WORK, "after.png"), "--width", "32", "--height", "24")
left = [p for p in glob.glob(os.path.join(TMP, "blendtool-render-*")) if os.path.isdir(p)]
check(not left, "render folders of killed runs are removed by the next render: %s" % left)
check(not glob.glob(os.path.join(dk, "out", ".*.lbtmp.*")), "temporary outputs of killed runs are left")
print("SIGKILL trials: %d render folders left by killed runs, all removed by the next run" % killed)

# ---- GNU parallel: the task list through parallel, --joblog, --resume-failed
dp = os.path.join(WORK, "par")
os.makedirs(dp)
jp = write_job(os.path.join(dp, "p.json"), dict(BASE, outputs={"mesh": {"resolution": 32}, "image": {
    "format": "png", "width": 64, "height": 48}}))
os.makedirs(os.path.join(dp, "out"))
os.makedirs(os.path.join(dp, "out", "cmp_0003.png"))  # a folder where task 3's image goes: it fails
cmd = "'%s' batch '%s' --list | cut -f1 | parallel -j2 --joblog '%s/j.log' '%s' batch '%s' --task {}" % (
    BT, jp, dp, BT, jp)
r = subprocess.run(["bash", "-c", cmd], capture_output=True, text=True)
log = [l.split("\t") for l in open(os.path.join(dp, "j.log")).read().splitlines()[1:]]
failed = [l[-1] for l in log if l[6] != "0"]
check(r.returncode == 1 and len(log) == 6 and failed == ["'%s' batch '%s' --task 3" % (BT, jp)] or
      (r.returncode == 1 and len(failed) == 1 and failed[0].endswith("--task 3")),
      "parallel: one failed job of 6, exit 1: rc %d %s" % (r.returncode, failed))
os.rmdir(os.path.join(dp, "out", "cmp_0003.png"))
r = subprocess.run(["bash", "-c", cmd.replace("parallel -j2", "parallel -j2 --resume-failed")],
                   capture_output=True, text=True)
log2 = [l.split("\t") for l in open(os.path.join(dp, "j.log")).read().splitlines()[1:]]
check(r.returncode == 0 and len(log2) == 7 and log2[-1][-1].endswith("--task 3") and log2[-1][6] == "0",
      "parallel --resume-failed reruns task 3 only: rc %d, %d entries" % (r.returncode, len(log2)))
check(digest(os.path.join(dp, "out")) == {k: v for k, v in digest(os.path.join(dp, "out")).items()}
      and len([n for n in os.listdir(os.path.join(dp, "out")) if n.endswith(".png")]) == 6,
      "parallel: all six images")

# ---- mesh outputs with sharp features and simplification: the cube in 12
# triangles (each corner with its face's normal in OBJ); a changed setting
# makes the task's identity differ, so the mesh is made again
CUBE = os.path.join(SRC, "tests", "data", "features", "cube.json")
cj = {"format": "libblend-job", "version": 1, "name": "cube", "scene": CUBE,
      "output_dir": "cube-out",
      "outputs": {"mesh": {"format": "obj", "resolution": 32, "features": True, "simplify": 0.1}}}
jsonschema.validate(cj, SCHEMA)
cdir = os.path.join(WORK, "cube")
os.makedirs(cdir)
r = bt("batch", write_job(os.path.join(cdir, "job.json"), cj))
objs = glob.glob(os.path.join(cdir, "cube-out", "*.obj"))
faces = [l for l in open(objs[0]).read().splitlines() if l.startswith("f ")] if objs else []
check(r.returncode == 0 and len(objs) == 1 and len(faces) == 12 and
      all("//" in f for f in faces),
      "job mesh output with features and simplify 0.1: the cube in %d triangles %s" %
      (len(faces), why(r)))
cj["outputs"]["mesh"]["simplify"] = 0
r = bt("batch", write_job(os.path.join(cdir, "job.json"), cj))
faces = [l for l in open(objs[0]).read().splitlines() if l.startswith("f ")] if objs else []
check(r.returncode == 0 and len(faces) > 1000,
      "simplify changed to 0: the task is redone, %d triangles %s" % (len(faces), why(r)))
cj["outputs"]["mesh"]["merge_flat"] = True
jsonschema.validate(cj, SCHEMA)
r = bt("batch", write_job(os.path.join(cdir, "job.json"), cj))
faces = [l for l in open(objs[0]).read().splitlines() if l.startswith("f ")] if objs else []
check(r.returncode == 0 and len(faces) == 12 and all("//" in f for f in faces),
      "merge_flat true: the task is redone, the cube in %d triangles %s" % (len(faces), why(r)))

# ---- blendtool compare
a, b = os.path.join(out1, "cmp_0000.png"), os.path.join(out1, "cmp_0004.png")
r = bt("compare", a, a)
check(r.returncode == 0 and r.stdout.startswith("MATCH"), "compare A A: " + r.stdout + r.stderr)
r = bt("compare", a, b)
check(r.returncode == 3 and r.stdout.startswith("DIFFER"), "compare A B: " + r.stdout + r.stderr)
r = bt("compare", a, b, "--fail", "1.0")
check(r.returncode == 0, "compare with a loose threshold: " + r.stdout)
r = bt("compare", a, os.path.join(out1, "cmp_sheet.png"))
check(r.returncode == 2 and "differ in size" in r.stderr, "compare different sizes: " + r.stderr)
r = bt("compare", a, os.path.join(WORK, "nope.png"))
check(r.returncode == 2, "compare a missing image: " + r.stderr)

finish()
