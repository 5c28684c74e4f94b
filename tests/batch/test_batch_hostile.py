#!/usr/bin/python3
"""blendtool batch against hostile and careless input, with real processes
and a real shell:

- the --slurm script run by sh from folders whose names hold quotes, $(),
  backticks, backslashes, newlines, spaces and non-ASCII: no byte of a path
  runs, the shard runs and writes its log; partitions Slurm cannot take
  are refused (exit 2, no script);
- --time and --mem in the script: defaults, options, measured from the
  shard logs of an earlier run;
- two jobs differing only in resolution, run at once into one folder:
  every manifest vouches for its own job's bytes, and a rerun of each
  gives its own reference; the same job run twice at once does each task
  once;
- names and patterns that cannot be one safe file name and one --list
  field are refused with the JSON path (exit 2, nothing created);
- GNU parallel on a job file whose path holds quotes and spaces, as the
  docs write the command line.

usage: test_batch_hostile.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import glob
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from batchlib import bt, check, finish, setup  # noqa: E402

BT, SRC, WORK = setup()

SCENE = os.path.join(SRC, "scenes", "default.json")
TINY = {"format": "libblend-job", "version": 1, "name": "tiny", "scene": SCENE,
        "outputs": {"mesh": {"resolution": 12}}}


def job_in(folder, job, fname="job.json"):
    os.makedirs(folder, exist_ok=True)
    p = os.path.join(folder, fname)
    with open(p, "w") as f:
        json.dump(dict(job, scene=SCENE), f)
    return p


def markers():
    """files a successful injection would have made, anywhere we look"""
    found = []
    for root in (WORK, "/tmp", os.getcwd()):
        for n in ("PWNED", "PWNED2", "PWNED3"):
            if os.path.exists(os.path.join(root, n)):
                found.append(os.path.join(root, n))
    for p in glob.glob(os.path.join(WORK, "**", "PWNED*"), recursive=True):
        found.append(p)
    return found


# ---- 1. the sbatch script, run by a real shell, from hostile folders
HOSTILE = [
    "p'$(touch PWNED)'p",
    'q"$(touch PWNED2)"q',
    "b`touch PWNED3`b",
    "back\\slash\\",
    "new\nline; touch PWNED",
    "sp ace  and\ttab",
    "pct%A%a%%",
    "ünï cödé ✓",
    "semi;colon&amp|pipe>redir<in",
    "dollar$HOME${IFS}",
]
for i, name in enumerate(HOSTILE):
    d = os.path.join(WORK, "inject", name)
    job = job_in(d, dict(TINY, name="t%d" % i))
    r = bt("batch", job, "--slurm", "--array-size", "1")
    if not check(r.returncode == 0, "%r: --slurm exit %d: %s" % (name, r.returncode, r.stderr)):
        continue
    script = r.stdout.rstrip("\n")
    check(script == os.path.join(os.path.realpath(d), "out", "t%d.sbatch" % i),
          "%r: the script's path is printed whole: %r" % (name, script))
    text = open(script).read()
    check(text.count("\n#SBATCH") >= 6 and all(
        not l.startswith("#SBATCH") or "\n" not in l for l in text.split("\n")),
        "%r: one line per #SBATCH directive" % name)
    # sh runs it as Slurm would, with the array index in the environment
    env = dict(os.environ, SLURM_ARRAY_TASK_ID="0")
    r = subprocess.run(["sh", script], capture_output=True, text=True, env=env, cwd=WORK,
                       timeout=300)
    check(r.returncode == 0, "%r: sh runs the script: exit %d %s" % (name, r.returncode, r.stderr))
    check(not markers(), "%r: nothing from the path ran: %s" % (name, markers()))
    out = os.path.join(d, "out")
    check(os.path.exists(os.path.join(out, "t%d_0000.ply" % i)), "%r: the shard meshed" % name)
    check(os.path.exists(os.path.join(out, ".libblend-manifest", "t%d_0000.json" % i)),
          "%r: the shard wrote its manifest" % name)
    check(os.path.exists(os.path.join(out, "logs", "t%d_shard_0.jsonl" % i)),
          "%r: the shard's log is where the script says: %s" % (
              name, os.listdir(os.path.join(out, "logs"))))
    for p in markers():
        os.unlink(p)

# partitions: what Slurm cannot take is refused, nothing written
d = os.path.join(WORK, "partition")
job = job_in(d, TINY)
for part in ["a\ntouch PWNED", "a'b", "a b", "a;b", "$(touch PWNED)", "", "a,,b", "ü"]:
    r = bt("batch", job, "--slurm", "--partition", part)
    check(r.returncode == 2 and "--partition" in r.stderr and "allowed" in r.stderr,
          "--partition %r: exit 2 with the rule: %d %s" % (part, r.returncode, r.stderr))
    check(not os.path.exists(os.path.join(d, "out")), "--partition %r: nothing created" % part)
r = bt("batch", job, "--slurm", "--partition", "debug,gpu-a.1")
check(r.returncode == 0 and "#SBATCH --partition=debug,gpu-a.1\n" in open(r.stdout.strip()).read(),
      "a valid partition list goes into the script")
check(not markers(), "no partition ran: %s" % markers())

# paths longer than blendtool's buffers are refused by name, never cut short
# (a cut output_dir would write somewhere else)
dl = os.path.join(WORK, "longpath")
for key, value in (("output_dir", "o" * 200 + "/" + "d" * 250 + ("/" + "e" * 250) * 16),
                   ("scene", "s" * 250 + ("/" + "t" * 250) * 33 + ".json")):
    jl = job_in(dl, TINY)
    doc = json.load(open(jl))
    doc[key] = value
    with open(jl, "w") as f:
        json.dump(doc, f)
    rl = bt("batch", jl)
    check(rl.returncode == 2 and "$.%s" % key in rl.stderr and "too long" in rl.stderr,
          "a %d-byte %s: exit 2 naming it: %d %s" % (len(value), key, rl.returncode, rl.stderr))
    check(not os.path.exists(os.path.join(dl, "o" * 200)), "%s too long: nothing created" % key)

# ---- 2. --time and --mem
text = open(r.stdout.strip()).read()
check("#SBATCH --time=30\n" in text and "#SBATCH --mem=4096M\n" in text,
      "defaults without measurements: 30 minutes per task, 4096 MB:\n" + text)
r = bt("batch", job, "--slurm", "--time", "7", "--mem", "300")
text = open(r.stdout.strip()).read()
check("#SBATCH --time=7\n" in text and "#SBATCH --mem=300M\n" in text, "--time 7 --mem 300")
for bad in (["--time", "0"], ["--time", "1x"], ["--mem", "-5"], ["--mem", "1e3"]):
    r = bt("batch", job, "--slurm", *bad)
    check(r.returncode == 2 and bad[0] in r.stderr, "%s: exit 2: %s" % (bad, r.stderr))
# measured: a shard log of an earlier run gives the time and the memory
dm = os.path.join(WORK, "measured")
jm = job_in(dm, dict(TINY, name="meas"))
os.makedirs(os.path.join(dm, "out", "logs"))
with open(os.path.join(dm, "out", "logs", "meas_shard_0.jsonl"), "w") as f:
    f.write(json.dumps({"event": "task_end", "task": 0, "status": "done", "seconds": 600.0,
                        "peak_rss_kb": 1048576}) + "\n")
    f.write(json.dumps({"event": "task_end", "task": 0, "status": "failed", "seconds": 9e6,
                        "peak_rss_kb": 9e9}) + "\n")
r = bt("batch", jm, "--slurm", "--array-size", "1")
text = open(r.stdout.strip()).read()
# 2 x 600 s x 1 task per shard = 20 min, + 5; 2 x 1 GiB + 256 MB
check("#SBATCH --time=25\n" in text and "#SBATCH --mem=2304M\n" in text,
      "measured from the shard log (failed tasks ignored):\n" + text)

# ---- 3. races on one output folder
RACE = {"format": "libblend-job", "version": 1, "name": "c", "scene": SCENE,
        "sweep": [{"path": "root.r", "values": [0.3, 0.35, 0.4, 0.45, 0.5, 0.55]}],
        "outputs": {"mesh": {"resolution": 48}}}
refs = {}
for res in (48, 56):
    d = os.path.join(WORK, "race-ref-%d" % res)
    j = job_in(d, dict(RACE, outputs={"mesh": {"resolution": res}}))
    r = bt("batch", j)
    check(r.returncode == 0, "reference %d: %s" % (res, r.stderr))
    man = {}
    for mf in glob.glob(os.path.join(d, "out", ".libblend-manifest", "*.json")):
        m = json.load(open(mf))
        man[os.path.basename(mf)] = m
    refs[res] = (d, man)
ident_of = {}
for res, (d, man) in refs.items():
    for n, m in man.items():
        ident_of[m["identity"]] = (res, n, m["outputs"][0]["hash"])


TRIALS = 15
bad_manifests = 0
for trial in range(TRIALS):
    d = os.path.join(WORK, "race2", "t%d" % trial)
    ja = job_in(d, dict(RACE, outputs={"mesh": {"resolution": 48}}), "a.json")
    jb = job_in(d, dict(RACE, outputs={"mesh": {"resolution": 56}}), "b.json")
    pa = subprocess.Popen([BT, "batch", ja], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    pb = subprocess.Popen([BT, "batch", jb], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    pa.communicate(timeout=600)
    pb.communicate(timeout=600)
    check(pa.returncode == 0 and pb.returncode == 0, "trial %d: both jobs succeed" % trial)
    out = os.path.join(d, "out")
    for mf in glob.glob(os.path.join(out, ".libblend-manifest", "*.json")):
        m = json.load(open(mf))
        res, n, h = ident_of.get(m["identity"], (None, None, None))
        ok = res is not None and m["outputs"][0]["hash"] == h
        # and the file in place is the bytes of that same job (the task ran under its lock)
        ref_file = os.path.join(refs[res][0], "out", m["outputs"][0]["file"]) if res else None
        ok = ok and open(os.path.join(out, m["outputs"][0]["file"]), "rb").read() == \
            open(ref_file, "rb").read()
        if not ok:
            bad_manifests += 1
            print("trial %d: %s vouches for other bytes" % (trial, mf))
    check([os.path.basename(p) for p in glob.glob(os.path.join(out, ".libblend-manifest", "*.lock"))]
          == ["tasks.lock"] and os.path.getsize(os.path.join(out, ".libblend-manifest", "tasks.lock")) == 0,
          "trial %d: one empty lock file, nothing else" % trial)
    # a rerun of either job gives its own reference bytes
    for j, res in ((ja, 48), (jb, 56)):
        r = bt("batch", j)
        same = all(open(os.path.join(out, m["outputs"][0]["file"]), "rb").read() ==
                   open(os.path.join(refs[res][0], "out", m["outputs"][0]["file"]), "rb").read()
                   for m in refs[res][1].values())
        check(r.returncode == 0 and same, "trial %d: a rerun of the %d job gives its bytes" % (trial, res))
check(bad_manifests == 0, "%d manifests vouched for another job's bytes in %d trials" % (
    bad_manifests, TRIALS))

# the same job twice at once: each task once
for trial in range(5):
    d = os.path.join(WORK, "race1", "t%d" % trial)
    j = job_in(d, RACE)
    ps = [subprocess.Popen([BT, "batch", j, "--log-json"], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True) for _ in range(2)]
    outs = [p.communicate(timeout=600)[0] for p in ps]
    starts = [json.loads(l)["task"] for o in outs for l in o.splitlines()
              if l.startswith("{") and json.loads(l)["event"] == "task_start"]
    check(all(p.returncode == 0 for p in ps), "same-job trial %d: both succeed" % trial)
    check(sorted(starts) == list(range(6)),
          "same-job trial %d: every task run exactly once: %s" % (trial, sorted(starts)))

# ---- 4. names and patterns
BADJOBS = [
    ({"name": "na\u0000me"}, "job.json:", "NUL"),
    ({"name": "."}, "$.name", "allowed"),
    ({"name": ".."}, "$.name", "allowed"),
    ({"name": ".hidden"}, "$.name", "allowed"),
    ({"name": "-x"}, "$.name", "allowed"),
    ({"name": "a b"}, "$.name", "allowed"),
    ({"name": "a'b"}, "$.name", "allowed"),
    ({"name": "a\tb"}, "$.name", "allowed"),
    ({"name": "x" * 201}, "$.name", "allowed"),
    ({"pattern": "\n_####"}, "$.pattern", "allowed"),
    ({"pattern": "{bogus}_####"}, "$.pattern", "unknown placeholder"),
    ({"pattern": "{name"}, "$.pattern", "unknown placeholder"),
    ({"pattern": "a_b"}, "$.pattern", "no #"),
    ({"pattern": ".x_####"}, "$.pattern", "allowed"),
    ({"pattern": "x\t####"}, "$.pattern", "allowed"),
    ({"pattern": "$(touch PWNED)####"}, "$.pattern", "allowed"),
]
for k, (extra, where, word) in enumerate(BADJOBS):
    d = os.path.join(WORK, "names", str(k))
    p = job_in(d, dict(TINY, **extra))
    for args in (["--list"], []):
        r = bt("batch", p, *args)
        check(r.returncode == 2 and where in r.stderr and word in r.stderr,
              "%r %s: exit 2 naming %s: %d %s" % (extra, args, where, r.returncode, r.stderr))
    check(not os.path.exists(os.path.join(d, "out")), "%r: nothing created" % extra)
# the JSON rules scenes follow (common/json_check.c): each key once, RFC 8259
RAWJOBS = [
    ('"name": "a", "name": "b"', "appears twice"),
    ('"name": "raw", "outputs": {"mesh": {"resolution": 012}}', "leading zero"),
    ('"name": "raw\x01"', "control character"),
    ('"name": "raw\xff"', "not UTF-8"),
]
for k, (members, word) in enumerate(RAWJOBS):
    d = os.path.join(WORK, "raw", str(k))
    os.makedirs(d, exist_ok=True)
    p = os.path.join(d, "job.json")
    with open(p, "wb") as f:
        f.write(('{"format": "libblend-job", "version": 1, "scene": %s, ' % json.dumps(SCENE)
                 ).encode() + members.encode("latin-1") + b"}")
    r = bt("batch", p, "--list")
    check(r.returncode == 2 and word in r.stderr and "job.json" in r.stderr,
          "raw job %d: exit 2 naming %r: %d %s" % (k, word, r.returncode, r.stderr))
    check(not os.path.exists(os.path.join(d, "out")), "raw job %d: nothing created" % k)
# a job file whose own name is unsafe needs "name"
d = os.path.join(WORK, "names", "stem")
p = job_in(d, {k: v for k, v in TINY.items() if k != "name"}, "bad name.json")
r = bt("batch", p, "--list")
check(r.returncode == 2 and "$.name" in r.stderr, "an unsafe job file name: %s" % r.stderr)
# non-ASCII names are names
d = os.path.join(WORK, "names", "utf8")
p = job_in(d, dict(TINY, name="Würfel", pattern="{name}_ü_####"))
r = bt("batch", p)
check(r.returncode == 0 and os.path.exists(os.path.join(d, "out", "Würfel_ü_0000.ply")),
      "UTF-8 names work: %s" % r.stderr)
check(not markers(), "no pattern ran: %s" % markers())

# ---- 5. GNU parallel as the docs write it, on a hostile job path
d = os.path.join(WORK, "parallel", "it's a \"job\" $(touch PWNED)")
job = job_in(d, dict(RACE, name="par"))
cmd = ('job=%s; "$BT" batch "$job" --list | cut -f1 | '
       'parallel -q -j2 --joblog "$LOG" "$BT" batch "$job" --task {}') % (
    "'" + job.replace("'", "'\\''") + "'")
r = subprocess.run(["bash", "-c", cmd], capture_output=True, text=True,
                   env=dict(os.environ, BT=BT, LOG=os.path.join(WORK, "par.log")), timeout=600)
check(r.returncode == 0, "parallel -q on a hostile path: %d %s" % (r.returncode, r.stderr[-600:]))
check(len(glob.glob(os.path.join(glob.escape(d), "out", "par_*.ply"))) == 6,
      "parallel: all six meshes")
check(not markers(), "nothing from the path ran under parallel: %s" % markers())

# ---- 6. a contact sheet of EXR outputs looks like the one of PNG outputs
# (linear light encoded as sRGB for the sheet, not put in as it is)
SHEET = {"format": "libblend-job", "version": 1, "name": "sh", "scene": SCENE,
         "sweep": [{"path": "root.r", "values": [0.3, 0.5]}],
         "outputs": {"image": {"width": 64, "height": 48},
                     "contact_sheet": {"columns": 2, "cell_width": 64, "cell_height": 48}}}
sheets = {}
for fmt in ("png", "exr"):
    d = os.path.join(WORK, "sheet-" + fmt)
    j = job_in(d, dict(SHEET, outputs=dict(SHEET["outputs"], image=dict(
        SHEET["outputs"]["image"], format=fmt))))
    r = bt("batch", j)
    sheets[fmt] = os.path.join(d, "out", "sh_sheet.png")
    check(r.returncode == 0 and os.path.exists(sheets[fmt]), "%s sheet: %s" % (fmt, r.stderr))
r = bt("compare", sheets["png"], sheets["exr"], "--fail", "0.02", "--fail-percent", "1")
check(r.returncode == 0, "the EXR job's sheet matches the PNG job's: %s %s" % (r.stdout, r.stderr))

finish()
