#!/usr/bin/python3
"""Signals and kills on real blendtool processes (docs/blendtool.md, "Signals").

SIGINT, SIGTERM and SIGHUP sent at random points of every phase (reading,
meshing, writing, exporting, rendering, copying) must end the command with
128 + the signal, leave nothing at the output path, no temporary file in the
output folder, no render folder and no povray process. SIGKILL must leave
nothing a rerun or a user would take for output: with unnamed temporary
files nothing at all; on the named fallback only a hidden file, which the next
run removes; a killed render's povray ends with it and its folder is removed
by the next render.

usage: test_signals.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time

BLENDTOOL, SRC, WORK = sys.argv[1:4]
S1 = os.path.join(SRC, "scenes", "bench-s1-three-spheres.json")
S2 = os.path.join(SRC, "scenes", "bench-s2-64-spheres.json")
rng = random.Random(20261201)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import fail, failures  # noqa: E402
checked = 0


def povray_pids(tmp):
    """povray processes rendering from our private TMPDIR"""
    out = set()
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                cmd = f.read()
        except OSError:
            continue
        if cmd.startswith(b"povray") and tmp.encode() in cmd:
            out.add(int(pid))
    return out


def fresh(name):
    d = os.path.join(WORK, name)
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(os.path.join(d, "out"))
    os.makedirs(os.path.join(d, "tmp"))
    return d


def env_for(d, named):
    e = dict(os.environ)
    e["TMPDIR"] = os.path.join(d, "tmp")
    e["LIBBLEND_POVRAY_INCLUDE"] = os.path.join(SRC, "povray_include")
    e.pop("LIBBLEND_OUTPUT_NAMED", None)
    if named:
        e["LIBBLEND_OUTPUT_NAMED"] = "1"
    return e


def run(args, env, stdin=None, sig=None, delay=0.0):
    """Start blendtool, send sig after delay; returns (rc, delivered, stderr)."""
    p = subprocess.Popen([BLENDTOOL] + args, stdin=stdin or subprocess.DEVNULL,
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
    delivered = False
    if sig is not None:
        time.sleep(delay)
        if p.poll() is None:
            p.send_signal(sig)
            delivered = True
    _, err = p.communicate(timeout=300)
    return p.returncode, delivered, err.decode(errors="replace")


def timed(args, env, stdin_file=None):
    t = time.monotonic()
    with open(stdin_file) if stdin_file else open(os.devnull) as fin:
        rc, _, err = run(args, env, stdin=fin)
    if rc != 0:
        fail(f"{args}: unsignalled run failed ({rc}): {err}")
    return time.monotonic() - t


def case(name, args_of, out_name, named, count_per_signal=4, stdin_file=None, need=8):
    """Random signals over the whole run of one command."""
    d = fresh(name + ("-named" if named else ""))
    env = env_for(d, named)
    outdir = os.path.join(d, "out")
    out = os.path.join(outdir, out_name)
    duration = timed(args_of(out), env, stdin_file)
    if not os.path.exists(out):
        fail(f"{name}: the unsignalled run wrote no {out}")
    os.remove(out)

    def one(sig, delay):
        """One signalled run and its checks; True when the signal arrived."""
        global checked
        with open(stdin_file) if stdin_file else open(os.devnull) as fin:
            rc, delivered, err = run(args_of(out), env, stdin=fin, sig=sig, delay=delay)
        label = f"{name}{' (named fallback)' if named else ''} {sig.name} at {delay:.3f} s"
        if not delivered or rc == 0:
            # finished first: then the output must be whole
            if rc != 0:
                fail(f"{label}: rc {rc}: {err}")
            if os.path.exists(out):
                os.remove(out)
            return False
        checked += 1
        if rc != 128 + sig:
            fail(f"{label}: exit status {rc}, want {128 + sig}: {err}")
        if os.path.lexists(out):
            fail(f"{label}: {out} exists after the signal")
            os.remove(out)
        left = os.listdir(outdir)
        if left:
            fail(f"{label}: left in the output folder: {left}")
        tmp_left = os.listdir(env["TMPDIR"])
        if tmp_left:
            fail(f"{label}: left in TMPDIR: {tmp_left}")
        if povray_pids(env["TMPDIR"]):
            fail(f"{label}: povray still running")
        return True

    delivered_n = 0
    sigs = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
    for sig in sigs:
        for i in range(count_per_signal):
            # stratified over the run: early, middle, late, any
            lo, hi = [(0.0, 0.3), (0.3, 0.6), (0.6, 0.97), (0.0, 0.97)][i % 4]
            delivered_n += one(sig, duration * rng.uniform(lo, hi))
    # The run was timed once; on a busy machine a later run may be much
    # quicker and the late signals come after it ended. Top up with signals
    # in the first 60 % (at most 12 more runs), so that enough arrive.
    for extra in range(12):
        if delivered_n >= need:
            break
        delivered_n += one(sigs[extra % 3], duration * rng.uniform(0.0, 0.6))
    if delivered_n < need:
        fail(f"{name}: only {delivered_n} signals arrived while it ran (want >= {need})")
    print(f"{name}{' named' if named else ''}: {delivered_n} signals during a {duration:.2f} s run")


def kill_case(name, args_of, out_name, named, trials=5):
    """SIGKILL at random points; then a rerun succeeds and cleans up."""
    global checked
    d = fresh("kill-" + name + ("-named" if named else ""))
    env = env_for(d, named)
    outdir = os.path.join(d, "out")
    out = os.path.join(outdir, out_name)
    duration = timed(args_of(out), env)
    with open(out, "rb") as f:
        ref = f.read()  # the same bytes every run (one thread)
    os.remove(out)
    for t in range(trials):
        delay = duration * rng.uniform(0.05, 0.95)
        rc, delivered, _ = run(args_of(out), env, sig=signal.SIGKILL, delay=delay)
        if not delivered:
            if os.path.exists(out):
                os.remove(out)
            continue
        checked += 1
        label = f"kill {name}{' (named)' if named else ''} at {delay:.3f} s"
        if os.path.lexists(out):
            # the kill came after the output was put in place (the process
            # was still ending; on a loaded machine that can take a while):
            # then it must be complete, the very bytes of an undisturbed run
            with open(out, "rb") as f:
                whole = f.read() == ref
            if not whole:
                fail(f"{label}: {out} exists after SIGKILL and is not the complete output")
            else:
                print(f"{label}: the output was complete before the kill")
            os.remove(out)
        left = os.listdir(outdir)
        if not named and left:
            fail(f"{label}: left in the output folder: {left}")
        for f in left:
            if not (f.startswith("." + out_name + ".lbtmp.")):
                fail(f"{label}: {f} could be taken for output")
        time.sleep(0.3)
        if povray_pids(env["TMPDIR"]):
            fail(f"{label}: povray outlived blendtool")
    # the next run succeeds and removes what killed runs left
    rc, _, err = run(args_of(out), env)
    if rc != 0 or not os.path.exists(out):
        fail(f"kill {name}: rerun failed ({rc}) {err}")
    left = [f for f in os.listdir(outdir) if f != out_name]
    if left:
        fail(f"kill {name}: the rerun left {left}")
    if name == "render" and os.listdir(env["TMPDIR"]):
        fail(f"kill render: stale render folders not removed: {os.listdir(env['TMPDIR'])}")


def batch_case():
    """blendtool batch goes on after each output, so a signal must end it at
    once there too (a farm's scheduler sends SIGTERM on a cancel or a time
    limit): 128 + the signal, the outputs finished before it whole (the
    bytes of an undisturbed run), nothing partial, and a rerun completes the
    job with the same bytes. Before 2026-12-05 the first output's commit held
    the signals for good and the job ran to its end."""
    global checked
    d = fresh("batch")
    env = env_for(d, False)

    def job(name):
        path = os.path.join(d, name + ".json")
        with open(path, "w") as f:
            json.dump({"format": "libblend-job", "version": 1, "name": "m", "scene": S2,
                       "sweep": [{"path": "root.args[0].radius",
                                  "range": {"from": 0.2, "to": 0.3, "count": 24}}],
                       "outputs": {"mesh": {"format": "ply", "resolution": 160}},
                       "output_dir": os.path.join(d, name)}, f)
        return path

    def plys(folder):
        return sorted(f for f in os.listdir(folder) if f.endswith(".ply"))

    ref_job = job("ref")
    duration = timed(["batch", ref_job, "--threads", "1"], env)
    ref_dir = os.path.join(d, "ref")
    ref = {f: open(os.path.join(ref_dir, f), "rb").read() for f in plys(ref_dir)}
    if len(ref) != 24:
        fail(f"batch: the undisturbed run wrote {len(ref)} meshes, want 24")
    n = 0
    for sig in (signal.SIGTERM, signal.SIGHUP, signal.SIGINT):
        for lo, hi in ((0.15, 0.4), (0.4, 0.8)):
            n += 1
            name = f"run{n}"
            path = job(name)
            out = os.path.join(d, name)
            delay = duration * rng.uniform(lo, hi)
            t = time.monotonic()
            rc, delivered, err = run(["batch", path, "--threads", "1"], env, sig=sig, delay=delay)
            took = time.monotonic() - t
            label = f"batch {sig.name} at {delay:.2f} s of {duration:.2f} s"
            if not delivered:
                continue
            checked += 1
            if rc != 128 + sig:
                fail(f"{label}: exit status {rc} after {took:.2f} s, want {128 + sig}: {err}")
            got = plys(out) if os.path.isdir(out) else []
            for f in got:
                if open(os.path.join(out, f), "rb").read() != ref.get(f):
                    fail(f"{label}: {f} is not the undisturbed run's")
            if not got or len(got) == 24:
                print(f"{label}: {len(got)} meshes before the signal")
            hidden = [os.path.join(r, f) for r, _, fs in os.walk(out) for f in fs
                      if "lbtmp" in f] if os.path.isdir(out) else []
            if hidden:
                fail(f"{label}: temporary files left: {hidden}")
            if os.listdir(env["TMPDIR"]):
                fail(f"{label}: left in TMPDIR: {os.listdir(env['TMPDIR'])}")
            rc, _, err = run(["batch", path, "--threads", "1"], env)
            done = {f: open(os.path.join(out, f), "rb").read() for f in plys(out)}
            if rc != 0 or done != ref:
                fail(f"{label}: the rerun gave {rc} and {len(done)} meshes "
                     f"({sum(done.get(f) == ref[f] for f in ref)} the undisturbed bytes): {err}")
    print(f"batch: {n} signalled runs during a {duration:.2f} s job, each resumed")


def main():
    os.makedirs(WORK, exist_ok=True)
    points = os.path.join(WORK, "points.txt")
    with open(points, "w") as f:
        for i in range(400000):
            f.write(f"{(i % 97) * 0.05 - 2.0} {(i % 89) * 0.05 - 2.0} {(i % 83) * 0.05 - 2.0}\n")
    for named in (False, True):
        case("mesh", lambda o: ["mesh", S2, "-o", o, "--resolution", "288", "--quiet"],
             "mesh.obj", named)
        case("eval", lambda o: ["eval", "--points", points, "-o", o, S2], "values.txt", named)
        case("render", lambda o: ["render", S1, "-o", o, "--width", "160", "--height", "120",
                                  "--threads", "1"], "image.png", named)
    # reading standard input that never ends: every signal ends it
    d = fresh("stdin")
    env = env_for(d, False)
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        r, w = os.pipe()
        rc, delivered, err = run(["eval", S1, "-o", os.path.join(d, "out", "v.txt")], env,
                                 stdin=r, sig=sig, delay=0.3)
        os.close(r)
        os.close(w)
        global checked
        checked += 1
        if not delivered or rc != 128 + sig or os.listdir(os.path.join(d, "out")):
            fail(f"eval waiting on stdin, {sig.name}: rc {rc}, delivered {delivered}: {err}")
    # a level set: the C evaluation, then OpenVDB's C++ writer (dlopen'd)
    case("vdb", lambda o: ["vdb", S2, "-o", o, "--resolution", "512", "--threads", "1",
                           "--quiet"], "s2.vdb", False)
    kill_case("vdb", lambda o: ["vdb", S2, "-o", o, "--resolution", "512", "--threads", "1",
                                "--quiet"], "s2.vdb", False)
    for named in (False, True):
        kill_case("mesh", lambda o: ["mesh", S2, "-o", o, "--resolution", "288", "--quiet"],
                  "mesh.obj", named)
    kill_case("render", lambda o: ["render", S1, "-o", o, "--width", "160", "--height", "120",
                                   "--threads", "1"], "image.png", False)
    batch_case()
    print(f"{checked} signalled runs checked")
    if checked < 60:
        fail(f"only {checked} signalled runs checked (want >= 60)")
    if failures:
        print(f"{len(failures)} failures")
        sys.exit(1)
    print("all signal checks passed")


main()
