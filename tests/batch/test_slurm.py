#!/usr/bin/python3
"""blendtool batch on a real Slurm cluster (single node, this machine):
an 8-task job in 4 array tasks gives the same bytes as a local run; an
array task killed mid-render leaves nothing corrupt, and resubmitting the
same script redoes only its unfinished task; an array task cancelled with
scancel (SIGTERM) ends within seconds with its finished outputs whole, and
the resubmission does the rest; the same kill for a job rendered by
Blender workers (8 tasks in 2 array tasks, one killed while its Blender
renders: the Blender goes with it).

usage: test_slurm.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import hashlib
import json
import os
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from batchlib import check, digest, finish, setup  # noqa: E402

BT, SRC, WORK = setup(clean=False)
shutil.rmtree(os.path.join(WORK, "jobs"), ignore_errors=True)
os.makedirs(os.path.join(WORK, "jobs"), exist_ok=True)
cluster = os.path.join(WORK, "cluster")


r = subprocess.run(["bash", os.path.join(SRC, "scripts", "slurm-cluster.sh"), "start", cluster],
                   capture_output=True, text=True)
if r.returncode:
    print("the cluster did not start:", r.stdout, r.stderr)
    sys.exit(1)
os.environ["SLURM_CONF"] = os.path.join(cluster, "slurm.conf")
# a second cluster beside the first (a user's beside the suite's): its own
# free ports, recorded in its folder, both answering
cluster2 = os.path.join(WORK, "cluster2")
r2 = subprocess.run(["bash", os.path.join(SRC, "scripts", "slurm-cluster.sh"), "start", cluster2],
                    capture_output=True, text=True)
check(r2.returncode == 0, "a second cluster starts beside the first: %s %s" % (r2.stdout, r2.stderr))
p1 = open(os.path.join(cluster, "ports")).read().split()
p2 = open(os.path.join(cluster2, "ports")).read().split() if r2.returncode == 0 else []
check(len(p1) == 2 and len(p2) == 2 and not set(p1) & set(p2),
      "the two clusters' ports differ: %s %s" % (p1, p2))
for c in (cluster, cluster2):
    q = subprocess.run(["sinfo", "-h", "-o", "%T"], capture_output=True, text=True, timeout=30,
                       env=dict(os.environ, SLURM_CONF=os.path.join(c, "slurm.conf")))
    check(q.returncode == 0 and q.stdout.strip() in ("idle", "mixed", "allocated"),
          "%s answers: %r %r" % (c, q.stdout, q.stderr))
subprocess.run(["bash", os.path.join(SRC, "scripts", "slurm-cluster.sh"), "stop", cluster2])


def proc_stat(pid):
    """(state letter, start time in clock ticks) of a process, or None"""
    try:
        with open("/proc/%s/stat" % pid) as f:
            rest = f.read().rsplit(")", 1)[1].split()
        return rest[0], rest[19]
    except (OSError, IndexError):
        return None


def proc_state(pid, started):
    """the state letter of the process pid that started at `started`, or
    None when it is gone (or the pid now names another process)"""
    st = proc_stat(pid)
    return st[0] if st and st[1] == started else None


def kill_mid_task(shard_log, task, shard):
    """Wait (up to 300 s) until the shard's log says the task started, then
    SIGKILL the array task's blendtool (its command line has `--shard
    SHARD`). Returns (killed, its children at that moment as (pid, start
    time))."""
    deadline = time.time() + 300
    while time.time() < deadline:
        if os.path.exists(shard_log):
            ev = [json.loads(l) for l in open(shard_log) if l.strip()]
            if any(e["event"] == "task_start" and e["task"] == task for e in ev):
                time.sleep(0.3)
                kids = []
                for pid in subprocess.run(["pgrep", "-f", "--", "--shard " + shard],
                                          capture_output=True, text=True).stdout.split():
                    try:
                        with open("/proc/%s/task/%s/children" % (pid, pid)) as f:
                            kids += [(k, proc_stat(k)[1]) for k in f.read().split()]
                    except (OSError, TypeError):
                        pass
                k = subprocess.run(["pkill", "-KILL", "-f", "--", "--shard " + shard])
                return k.returncode == 0, kids
        time.sleep(0.05)
    return False, []


def resubmit(script, out, shards):
    """sbatch --wait the script again; (its result, the tasks the shards'
    logs say were done by it)"""
    logs = [os.path.join(out, "logs", "farm_shard_%d.jsonl" % i) for i in range(shards)]
    before = [len(open(l).readlines()) for l in logs]
    r = subprocess.run(["sbatch", "--wait", script], capture_output=True, text=True, timeout=600)
    redone = []
    for log, n in zip(logs, before):
        redone += [json.loads(l)["task"] for l in open(log).readlines()[n:]
                   if '"task_end"' in l and json.loads(l)["status"] == "done"]
    return r, redone


try:
    JOB = {"format": "libblend-job", "version": 1, "name": "farm",
           "scene": os.path.join(SRC, "scenes", "bernhardt-compare-local.json"),
           "sweep": [{"path": "root.args[0].center[0]", "range": {"from": -0.8, "to": -0.3, "count": 8}}],
           "outputs": {"mesh": {"resolution": 40}, "image": {"width": 120, "height": 90},
                       "contact_sheet": {"columns": 4}}}

    def job_in(name, job=JOB):
        d = os.path.join(WORK, "jobs", name)
        os.makedirs(d)
        p = os.path.join(d, "farm.json")
        json.dump(job, open(p, "w"))
        return d, p

    # the local reference
    dl, jl = job_in("local")
    r = subprocess.run([BT, "batch", jl], capture_output=True, text=True)
    check(r.returncode == 0, "local run: " + r.stderr[-500:])
    ref = digest(os.path.join(dl, "out"))
    # 8 meshes and images, the sheet, 8 manifests and the (empty) task lock file
    check(len(ref) == 8 * 2 + 1 + 8 + 1 and ref.get(".libblend-manifest/tasks.lock") ==
          hashlib.sha256(b"").hexdigest(), "local outputs: %d files" % len(ref))

    # through Slurm: 4 array tasks of 2 tasks each
    ds, js = job_in("slurm")
    t0 = time.time()
    r = subprocess.run([BT, "batch", js, "--submit", "--array-size", "4"], capture_output=True,
                       text=True, timeout=600)
    took = time.time() - t0
    check(r.returncode == 0, "batch --submit: %s %s" % (r.stdout, r.stderr[-800:]))
    check(digest(os.path.join(ds, "out")) == ref,
          "Slurm's outputs are byte-identical to the local run's (%.1f s)" % took)
    logs = sorted(os.listdir(os.path.join(ds, "out", "logs")))
    check(len([l for l in logs if l.endswith(".jsonl")]) == 4 and
          len([l for l in logs if l.endswith(".log")]) == 4, "one log per array task: %s" % logs)

    # hostile folder names through the real sbatch: the #SBATCH lines keep
    # one line each, nothing from a path runs, the logs land in OUT/logs
    tiny = {"format": "libblend-job", "version": 1, "name": "tiny",
            "scene": os.path.join(SRC, "scenes", "default.json"),
            "outputs": {"mesh": {"resolution": 12}}}
    for k, name in enumerate(["p'$(touch PWNED)'p \"q\" `touch PWNED` ü",
                              "new\nline$(touch PWNED)\\%A"]):
        dh, jh = job_in(os.path.join("hostile%d" % k, name), tiny)
        r = subprocess.run([BT, "batch", jh, "--submit", "--array-size", "1"], capture_output=True,
                           text=True, timeout=600, cwd=dh)
        check(r.returncode == 0, "hostile folder %r: submitted: %s" % (name, r.stderr[-500:]))
        hout = os.path.join(dh, "out")
        check(os.path.exists(os.path.join(hout, "tiny_0000.ply")), "hostile folder %r: meshed" % name)
        check(os.path.exists(os.path.join(hout, "logs", "tiny_shard_0.jsonl")),
              "hostile folder %r: the shard's log: %s" % (name, os.listdir(os.path.join(hout, "logs"))))
        pw = [p for p in (os.path.join(dh, "PWNED"), os.path.join(WORK, "PWNED"), "/tmp/PWNED")
              if os.path.exists(p)]
        check(not pw, "hostile folder %r: nothing from the path ran: %s" % (name, pw))

    # kill one array task mid-render, then resubmit the same script
    # (renders of about 1.7 s, killed 0.3 s after the task starts: until
    # 2026-12-05 they were 320 x 240, 6.8 s each, for the same check, 112 s
    # of the test)
    slow = dict(JOB, outputs={"mesh": {"resolution": 40},
                              "image": {"width": 128, "height": 96, "quality": 11}})
    dk, jk = job_in("kill", slow)
    dref, jref = job_in("kill-ref", slow)
    r = subprocess.run([BT, "batch", jref], capture_output=True, text=True)
    kref = digest(os.path.join(dref, "out"))
    r = subprocess.run([BT, "batch", jk, "--slurm", "--array-size", "4"], capture_output=True, text=True)
    script = r.stdout.strip()
    check(r.returncode == 0 and script.endswith("farm.sbatch"), "batch --slurm writes the script: " + r.stdout)
    p = subprocess.Popen(["sbatch", "--wait", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True)
    # shard 2 holds tasks 4 and 5: kill it while task 5 renders
    killed, _ = kill_mid_task(os.path.join(dk, "out", "logs", "farm_shard_2.jsonl"), 5, "2/4")
    out, err = p.communicate(timeout=600)
    check(killed, "array task 2 was killed mid-task")
    check(p.returncode != 0, "sbatch --wait reports the killed array task: exit %d" % p.returncode)
    kout = os.path.join(dk, "out")
    for n, h in digest(kout).items():
        check(kref.get(n) == h, "after the kill, %s is complete (the reference's bytes)" % n)
    check(not os.path.exists(os.path.join(kout, ".libblend-manifest", "farm_0005.json")),
          "the killed task has no manifest")
    r, redone = resubmit(script, kout, 4)
    check(r.returncode == 0, "resubmitting the script succeeds: " + r.stderr)
    check(redone == [5], "the resubmission redid only the killed task: %s" % redone)
    check({k: v for k, v in digest(kout).items() if k != "farm_sheet.png"} == kref,
          "and every output now equals the reference")

    # scancel (a farm's cancel; a time limit does the same): Slurm sends
    # SIGTERM to the array task's processes, and its blendtool must end at
    # once, its finished outputs whole, not run its remaining tasks (until
    # 2026-12-05 the first output's commit held the signals to the job's end,
    # so a cancelled array task ran on until KillWait's SIGKILL). Meshes
    # only, 40 tasks of about 0.15 s: seconds of work left when the cancel
    # comes, a few for the reference and the resubmission
    quick = dict(JOB, scene=os.path.join(SRC, "scenes", "bench-s2-64-spheres.json"),
                 sweep=[{"path": "root.args[0].radius", "range": {"from": 0.2, "to": 0.3,
                                                                  "count": 40}}],
                 outputs={"mesh": {"resolution": 256}})
    dcr, jcr = job_in("cancel-ref", quick)
    r = subprocess.run([BT, "batch", jcr], capture_output=True, text=True)
    check(r.returncode == 0, "cancel: the local reference: " + r.stderr[-500:])
    cref = digest(os.path.join(dcr, "out"))
    dc, jc = job_in("cancel", quick)
    r = subprocess.run([BT, "batch", jc, "--slurm", "--array-size", "1"], capture_output=True,
                       text=True)
    script = r.stdout.strip()
    check(r.returncode == 0, "cancel: batch --slurm writes the script: " + r.stderr[-500:])
    sub = subprocess.run(["sbatch", "--parsable", script], capture_output=True, text=True,
                         timeout=60)
    jobid = sub.stdout.strip().split(";")[0]
    check(sub.returncode == 0 and jobid.isdigit(), "cancel: submitted: %r %r" % (sub.stdout, sub.stderr))
    clog = os.path.join(dc, "out", "logs", "farm_shard_0.jsonl")
    deadline, pids = time.time() + 300, []
    while time.time() < deadline and not pids:
        if os.path.exists(clog) and any(json.loads(l)["event"] == "task_start" and
                                        json.loads(l)["task"] == 2
                                        for l in open(clog) if l.strip()):
            for pid in subprocess.run(["pgrep", "-f", "--", "--shard 0/1"], capture_output=True,
                                      text=True).stdout.split():
                st = proc_stat(pid)
                if st:
                    pids.append((pid, st[1]))
        else:
            time.sleep(0.05)
    check(pids, "cancel: the array task reached its third task")
    t = time.time()
    subprocess.run(["scancel", jobid], timeout=60)
    while time.time() - t < 60 and any(proc_state(q, s0) not in (None, "Z", "X") for q, s0 in pids):
        time.sleep(0.05)
    ended = time.time() - t
    check(ended < 5, "cancel: the array task's blendtool ended %.2f s after scancel (want < 5 s; "
          "Slurm's SIGKILL would come at 30)" % ended)
    cout = os.path.join(dc, "out")
    done = [json.loads(l)["task"] for l in open(clog)
            if '"task_end"' in l and json.loads(l)["status"] == "done"]
    print("cancel: the array task's blendtool ended %.2f s after scancel, %d of 40 tasks done"
          % (ended, len(done)))
    check(2 <= len(done) < 40, "cancel: it stopped partway (%d tasks done of 40)" % len(done))
    for n, h in digest(cout).items():
        check(cref.get(n) == h, "after scancel, %s is complete (the reference's bytes)" % n)
    r, redone = resubmit(script, cout, 1)
    check(r.returncode == 0 and sorted(redone) == [k for k in range(40) if k not in done],
          "cancel: the resubmission did the rest: %s (%s)" % (redone, r.stderr[-300:]))
    check(digest(cout) == cref, "cancel: and every output now equals the reference")

    # A Blender job (outputs.image.renderer "blender"): 8 tasks in 2 array
    # tasks, each running one worker Blender; array task 1 is killed while
    # its last task renders (its Blender goes with it), the resubmission
    # redoes exactly that task, and every output equals a local run's
    bjob = dict(JOB, outputs={"image": {"width": 240, "height": 180, "renderer": "blender",
                                        "samples": 32, "mesh": 40}})
    dbl, jbl = job_in("blender-local", bjob)
    r = subprocess.run([BT, "batch", jbl], capture_output=True, text=True)
    check(r.returncode == 0, "Blender job, local run: " + r.stderr[-800:])
    bref = digest(os.path.join(dbl, "out"))
    dbk, jbk = job_in("blender-slurm", bjob)
    r = subprocess.run([BT, "batch", jbk, "--slurm", "--array-size", "2"], capture_output=True,
                       text=True)
    script = r.stdout.strip()
    check(r.returncode == 0, "Blender job: batch --slurm: " + r.stderr[-500:])
    p = subprocess.Popen(["sbatch", "--wait", script], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    killed, workers = kill_mid_task(os.path.join(dbk, "out", "logs", "farm_shard_1.jsonl"), 7,
                                    "1/2")
    out, err = p.communicate(timeout=600)
    check(killed and workers, "Blender job: array task 1 killed mid-render (its workers %s)" % workers)
    check(p.returncode != 0, "Blender job: sbatch --wait reports the kill: exit %d" % p.returncode)
    # a SIGKILLed Blender may take a moment to unmap its memory on a loaded
    # machine, and once dead it stays a zombie until whoever inherited it
    # (slurmstepd or the container's init) reaps it: both count as ended
    deadline = time.time() + 30
    while True:
        alive = [(w, proc_state(w, t)) for w, t in workers if proc_state(w, t) not in (None, "Z", "X")]
        if not alive or time.time() > deadline:
            break
        time.sleep(0.2)
    check(not alive, "the killed array task's Blender ended with it (30 s): %s alive" % alive)
    bout = os.path.join(dbk, "out")
    check(not os.path.exists(os.path.join(bout, "farm_0007.png")) and
          not os.path.exists(os.path.join(bout, ".libblend-manifest", "farm_0007.json")),
          "Blender job: the killed task left no image and no manifest")
    r, redone = resubmit(script, bout, 2)
    check(r.returncode == 0, "Blender job: the resubmission succeeds: " + r.stderr)
    check(redone == [7], "Blender job: the resubmission redid only the killed task: %s" % redone)
    got = digest(bout)
    check(got == bref, "Blender job: Slurm's outputs equal the local run's: %s" %
          sorted(set(got.items()) ^ set(bref.items()))[:6])
finally:
    subprocess.run(["bash", os.path.join(SRC, "scripts", "slurm-cluster.sh"), "stop", cluster])
finish()
