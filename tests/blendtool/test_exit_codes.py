#!/usr/bin/python3
"""Every row of the exit-status table (docs/blendtool.md) for every command it
applies to, and the output-path rules (symlinks, devices, FIFOs, folders,
modes): exit status, one message line naming the file, and nothing written
where nothing may be. Signals (130 / 143 / 129) are test_signals.py's.

usage: test_exit_codes.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import json
import os
import shutil
import stat
import subprocess
import sys
import threading

BT, SRC, WORK = sys.argv[1:4]
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
S1 = os.path.join(SRC, "scenes", "bench-s1-three-spheres.json")
S2 = os.path.join(SRC, "scenes", "bench-s2-64-spheres.json")
ENV = dict(os.environ, LIBBLEND_POVRAY_INCLUDE=os.path.join(SRC, "povray_include"))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import fail, failures  # noqa: E402
rows = 0


def bt(*args, stdin=None, stdout=subprocess.PIPE):
    return subprocess.run([BT, *args], stdin=stdin, stdout=stdout, stderr=subprocess.PIPE,
                          env=ENV, timeout=300)


def expect(label, args, code, msg=None, names=None, absent=(), stdout=subprocess.PIPE,
           stdin=None):
    global rows
    rows += 1
    r = bt(*args, stdin=stdin, stdout=stdout)
    err = r.stderr.decode(errors="replace")
    if r.returncode != code:
        fail(f"{label}: exit {r.returncode}, want {code}: {err!r}")
    if code != 0:
        # povray's own progress streams to stderr too: count blendtool's lines
        lines = [l for l in err.splitlines() if l.startswith("blendtool")]
        if len(lines) != 1:
            fail(f"{label}: {len(lines)} message lines, want 1: {err!r}")
        if msg and msg not in err:
            fail(f"{label}: message {err!r} lacks {msg!r}")
        if names and names not in err:
            fail(f"{label}: message {err!r} does not name {names!r}")
    for p in absent:
        if os.path.lexists(p):
            fail(f"{label}: {p} was written")
            os.remove(p)


def write(name, text):
    p = os.path.join(WORK, name)
    with open(p, "w") as f:
        f.write(text)
    return p


def careless_rows():
    """What careless users tried (issue 28): each gets its documented code, a
    message naming the place and what is allowed, and nothing created."""
    global rows
    sph = {"type": "sphere", "center": [0, 0, 0], "radius": 1}
    many = write("many.json", json.dumps({
        "format": "libblend-scene", "version": 1, "convention": "zero",
        "bounds": {"min": [-1] * 3, "max": [1] * 3},
        "defs": {"a": {"type": "min", "args": [sph] * 60000}},
        "root": {"type": "min", "args": [{"ref": "a"}] + [sph] * 50000}}))
    o = os.path.join(WORK, "many.ply")
    for cmd, extra in (("validate", []), ("info", []), ("mesh", ["-q", "-o", o])):
        expect(f"{cmd}: over 100000 nodes", [cmd, many, *extra], 2, "more than 100000 nodes", many,
               [o])
    nl = write("nl.json", json.dumps({"format": "libblend-scene", "version": 1,
                                      "convention": "zero", "defs": {"a\nb": sph},
                                      "root": {"ref": "a\nb"}}))
    expect("info: a def name with a newline", ["info", nl], 2, "control character", nl)
    # local unions' compile work counts against its limit as it is done: a
    # flat local_union of 256 spheres (a left fold: each fold evaluates all
    # before it) is refused with the node's path, in seconds, by every command
    import math
    import time
    ring = [{"type": "sphere", "radius": 0.3,
             "center": [1.5 * math.cos(2 * math.pi * i / 256), 1.5 * math.sin(2 * math.pi * i / 256),
                        0.2 * math.sin(7 * i)]} for i in range(256)]
    flat = write("flat-local.json", json.dumps({
        "format": "libblend-scene", "version": 1, "convention": "zero",
        "bounds": {"min": [-3] * 3, "max": [3] * 3},
        "root": {"type": "local_union", "args": ring}}))
    for cmd, extra in (("validate", []), ("info", []), ("mesh", ["-q", "-o", o])):
        t = time.monotonic()
        expect(f"{cmd}: a local union over the compile-cost limit", [cmd, flat, *extra], 2,
               "compile-cost limit", "$.root", [o])
        if time.monotonic() - t > 60:
            fail(f"{cmd}: the compile-cost refusal took {time.monotonic() - t:.0f} s")
    # --set values and paths
    for v, what in (("root.r=0.5junk", "not one JSON value"), ("root.r=1=2", "not one JSON value"),
                    ("root.r=0.5]", "not one JSON value"), ("root.r=1e999", "beyond the range"),
                    ("root.args[01].radius=0.5", "leading zeros"),
                    ("root.args[+1].radius=0.5", "leading zeros")):
        expect(f"mesh --set {v}", ["mesh", S1, "-q", "--set", v, "-o", o], 2, what, v, [o])
    # batch: refused jobs create nothing
    d = os.path.join(WORK, "careless")
    os.makedirs(d, exist_ok=True)
    outdir = os.path.join(d, "out")

    def job(name, **kw):
        j = {"format": "libblend-job", "version": 1, "scene": S1,
             "outputs": {"mesh": {"resolution": 8}}}
        j.update(kw)
        return write(os.path.join("careless", name + ".json"), json.dumps(j))
    cases = [
        ("a bad set path", job("badset", set={"root.nope.radius": 1}), "root.nope"),
        ("/etc/passwd as the scene", job("passwd", scene="/etc/passwd"), "/etc/passwd"),
        ("a sweep over the whole double range",
         job("huge", sweep=[{"path": "root.r", "range": {"from": -1e308, "to": 1e308, "count": 3}}]),
         "magnitude"),
    ]
    for label, path, what in cases:
        for extra in ([], ["--list"]):
            expect(f"batch {extra}: {label}", ["batch", path, *extra], 2, what, None, [outdir])
    plain = job("plain")
    expect("batch --frames -1-2", ["batch", plain, "--frames", "-1-2"], 2, "0 <= A <= B", None,
           [outdir])
    expect("batch --frames 2-2 without frames", ["batch", plain, "--frames", "2-2"], 2,
           "no \"frames\"", None, [outdir])
    expect("batch --sheet on a mesh-only job", ["batch", plain, "--sheet"], 2, "no image outputs",
           None, [outdir])
    # compare on hostile images: the header's size is refused before any pixel
    # is decoded (a 40000 x 40000 PNG of a few hundred bytes), a FIFO or a
    # device is not read at all
    import struct
    import zlib

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    huge_png = os.path.join(WORK, "huge.png")
    with open(huge_png, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 40000, 40000, 8, 6, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(b"\0" * 160001 * 4)) + chunk(b"IEND", b""))
    small = os.path.join(WORK, "small.png")
    with open(small, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(b"\0" + b"\x10" * 6 + b"\0" + b"\x20" * 6))
                + chunk(b"IEND", b""))
    expect("compare: a small PNG declaring 40000 x 40000", ["compare", huge_png, small], 2,
           "declares 40000x40000", huge_png)
    expect("compare: sizes differ", ["compare", small, huge_png], 2, "allowed", huge_png)
    expect("compare: /dev/zero", ["compare", "/dev/zero", small], 2, "not a regular file",
           "/dev/zero")
    fifo = os.path.join(WORK, "img-fifo")
    if not os.path.exists(fifo):
        os.mkfifo(fifo)
    expect("compare: a FIFO", ["compare", small, fifo], 2, "not a regular file", fifo)
    expect("compare: the same image", ["compare", small, small], 0)
    # a log that cannot be written: exit 1 and said, the outputs complete
    rows += 1
    r = bt("batch", plain, "--log", "/dev/full")
    err = r.stderr.decode(errors="replace")
    if r.returncode != 1 or "writing the log failed" not in err or "/dev/full" not in err:
        fail(f"batch --log /dev/full: exit {r.returncode}: {err!r}")
    if not os.path.exists(os.path.join(outdir, "plain_0000.ply")):
        fail("batch --log /dev/full: the task's output is missing")


def main():
    out = {ext: os.path.join(WORK, "out." + ext) for ext in ("ply", "pov", "png", "txt")}
    outputs = [("mesh", ["mesh", S1, "--resolution", "16", "-q", "--format", "ply", "-o"],
                out["ply"]),
               ("pov", ["pov", S1, "-o"], out["pov"]),
               ("render", ["render", S1, "--width", "32", "--height", "24", "-o"], out["png"]),
               ("eval", ["eval", "--points", write("p.txt", "0 0 0\n"), S1, "-o"], out["txt"])]
    bad = write("bad.json", '{"format": "libblend-scene", "version": 1, "convention": "zero",\n'
                            ' "root": {"type": "sphere", "radius": -2}}\n')
    # 0: success, every command
    for name, args, o in outputs:
        expect(f"{name} succeeds", args + [o], 0)
        if not os.path.exists(o):
            fail(f"{name}: no output")
    expect("validate succeeds", ["validate", S1, S2], 0)
    # the documented extremes are accepted: bounds at +-1e9, underflowing
    # numbers and trailing comments in points
    expect("mesh at --bounds +-1e9", ["mesh", S1, "-q", "--resolution", "8", "--bounds",
                                      "-1e9,-1e9,-1e9,1e9,1e9,1e9", "-o", out["ply"]], 0)
    r1 = subprocess.run([BT, "eval", S1], input=b"1e-400 0 0 # underflows to 0\n2.5e-320 0 0\n",
                        capture_output=True)
    r0 = subprocess.run([BT, "eval", S1], input=b"0 0 0\n2.5e-320 0 0\n", capture_output=True)
    if r1.returncode != 0 or r1.stdout != r0.stdout:
        fail(f"eval of 1e-400 with a comment: {r1.returncode} {r1.stdout!r} vs {r0.stdout!r}")
    expect("info succeeds", ["info", "--json", S2], 0)
    for o in out.values():
        os.remove(o)

    # 2: bad input or arguments, every command
    for name, args, o in outputs:
        cmd = args[0]
        rest = [a for a in args[1:] if a != S1]
        expect(f"{name}: bad scene", [cmd, *rest[:-1], bad, rest[-1], o], 2,
               "$.root.radius: -2 is out of range", bad, [o])
        expect(f"{name}: missing scene", [cmd, *rest[:-1], os.path.join(WORK, "none.json"),
                                          rest[-1], o], 2, "cannot open the scene file",
               "none.json", [o])
        expect(f"{name}: unknown option", args + [o, "--frobnicate"], 2, "unknown option", None,
               [o])
        expect(f"{name}: output is a folder", args + [WORK], 2, None, WORK)
        missing = os.path.join(WORK, "no", os.path.basename(o))
        expect(f"{name}: output in a missing folder", args + [missing], 2,
               "cannot create the output file there", missing)
        expect(f"{name}: /dev/zero as the scene", [cmd, *rest[:-1], "/dev/zero", rest[-1], o], 2,
               "larger than 67108864 bytes", "/dev/zero", [o])
    expect("validate: bad scene", ["validate", S1, bad], 2, "$.root.radius", bad)
    expect("info: bad scene", ["info", bad], 2, "$.root.radius", bad)
    expect("validate: /dev/urandom", ["validate", "/dev/urandom"], 2, "larger than", "/dev/urandom")
    big = os.path.join(WORK, "big.json")
    with open(big, "wb") as f:
        f.truncate(64 * 1024 * 1024 + 1)
    expect("validate: a scene over 64 MiB", ["validate", big], 2, "67108865 bytes", big)
    # the instruction limit: the same code and the file name from every command
    defs = {"d0": {"type": "sphere", "center": [0, 0, 0], "radius": 1}}
    for i in range(1, 19):
        defs[f"d{i}"] = {"type": "min", "args": [{"ref": f"d{i - 1}"},
                                                 {"ref": f"d{i - 1}", "translate": [2 ** i, 0, 0]}]}
    huge = write("huge.json", json.dumps({"format": "libblend-scene", "version": 1,
                                          "convention": "zero", "bounds": {"min": [-1] * 3,
                                                                           "max": [1] * 3},
                                          "defs": defs, "root": {"ref": "d18"}}))
    for cmd, extra in (("validate", []), ("info", []), ("mesh", ["-o", out["ply"]]),
                       ("pov", ["-o", out["pov"]]), ("eval", ["-o", out["txt"]])):
        expect(f"{cmd}: the instruction limit", [cmd, huge, *extra], 2,
               "more than 200000 instructions", huge, list(out.values()), stdin=subprocess.DEVNULL)
    # the cost limit
    def sph(x):
        return {"type": "sphere", "center": [x, 0, 0], "radius": 0.5}
    n = {"type": "min", "args": [sph(0.01 * i) for i in range(200)]}
    for d in range(4):
        n = {"type": "displacement", "op": "union", "r": 0.3, "p": 2, "bulge": {"range": True},
             "args": [n, sph(1 + d)]}
    costly = write("costly.json", json.dumps({"format": "libblend-scene", "version": 1,
                                              "convention": "zero", "root": n}))
    expect("validate: the cost limit", ["validate", costly], 2,
           "allowed: at most 64 times the tape size", costly)
    expect("mesh: the memory cap", ["mesh", S2, "-q", "--resolution", "8192", "-o", out["ply"]],
           2, "a resolution of at most", S2, [out["ply"]])
    expect("mesh: --resolution with --cell-size",
           ["mesh", S1, "--resolution", "8", "--cell-size", "0.1", "-o", out["ply"]], 2,
           "both given", None, [out["ply"]])
    expect("a control character in an argument stays one line",
           ["mesh", S1, "-o", out["ply"], "--frob\nnicate"], 2, "unknown option --frob\\nnicate")
    expect("eval: bad points", ["eval", S1, "-o", out["txt"]], 2, "<stdin>:1: expected three",
           None, [out["txt"]], stdin=open(write("bp.txt", "1 2\n")))
    expect("eval: an endless line", ["eval", "--points", "/dev/zero", S1, "-o", out["txt"]], 2,
           "line longer than 4096 bytes", "/dev/zero", [out["txt"]])

    # 1: failure writing output, every command (a full device, a full stdout)
    for name, args, o in outputs:
        expect(f"{name}: output on a full device", args + ["/dev/full"], 1,
               "No space left on device", "/dev/full")
    expect("eval: stdout full", ["eval", S1], 1, "No space left on device",
           stdin=open(write("p1.txt", "0 0 0\n")), stdout=open("/dev/full", "w"))
    for cmd, a in (("validate", [S1]), ("info", [S1]), ("info", ["--json", S1])):
        expect(f"{cmd} {' '.join(a[:-1])}: stdout full", [cmd, *a], 1,
               "writing to standard output failed", stdout=open("/dev/full", "w"))
    env_noinc = dict(ENV, LIBBLEND_POVRAY_INCLUDE=os.path.join(WORK, "nowhere"))
    r = subprocess.run([BT, "render", S1, "--width", "32", "--height", "24", "-o", out["png"]],
                       capture_output=True, env=env_noinc)
    global rows
    rows += 1
    # refused before povray starts, naming the file looked for and the fix
    nowhere = os.path.join(WORK, "nowhere", "libblend.inc").encode()
    if r.returncode != 1 or os.path.exists(out["png"]) or nowhere not in r.stderr or \
            b"LIBBLEND_POVRAY_INCLUDE" not in r.stderr or b"Persistence of Vision" in r.stderr:
        fail(f"render without libblend.inc: exit {r.returncode}: {r.stderr[-300:]!r}")
    if not stat.S_ISCHR(os.stat("/dev/full").st_mode):
        fail("/dev/full is no longer a character device")

    # output paths: a symlink is followed (the link stays), devices and FIFOs
    # are written directly, modes are 0666 less the umask or kept
    old = os.umask(0o027)
    try:
        for name, args, o in outputs:
            target = os.path.join(WORK, "target-" + os.path.basename(o))
            link = os.path.join(WORK, "link-" + os.path.basename(o))
            for p in (target, link):
                if os.path.lexists(p):
                    os.remove(p)
            os.symlink(os.path.basename(target), link)
            expect(f"{name} through a dangling symlink", args + [link], 0)
            if not os.path.islink(link) or not os.path.isfile(target):
                fail(f"{name}: the symlink was replaced or its target not written")
            elif stat.S_IMODE(os.stat(target).st_mode) != 0o640:
                fail(f"{name}: new file mode {oct(os.stat(target).st_mode)}, want 0o640 (umask 027)")
            os.chmod(target, 0o604)
            expect(f"{name} over an existing file through the symlink", args + [link], 0)
            if stat.S_IMODE(os.stat(target).st_mode) != 0o604 or not os.path.islink(link):
                fail(f"{name}: the existing mode was not kept ({oct(os.stat(target).st_mode)})")
            expect(f"{name} to /dev/null", args + ["/dev/null"], 0)
            if not stat.S_ISCHR(os.stat("/dev/null").st_mode):
                fail(f"{name}: /dev/null was replaced")
            fifo = os.path.join(WORK, "fifo")
            if os.path.lexists(fifo):
                os.remove(fifo)
            os.mkfifo(fifo)
            got = {}

            def reader():
                with open(fifo, "rb") as f:
                    got["n"] = len(f.read())
            t = threading.Thread(target=reader, daemon=True)
            t.start()
            expect(f"{name} into a FIFO", args + [fifo], 0)
            t.join(60)
            if not stat.S_ISFIFO(os.stat(fifo).st_mode) or not got.get("n"):
                fail(f"{name}: the FIFO was replaced or got nothing ({got})")
            left = [f for f in os.listdir(WORK) if ".lbtmp." in f]
            if left:
                fail(f"{name}: temporary files left: {left}")
    finally:
        os.umask(old)
    careless_rows()
    print(f"{rows} exit-status and output-path rows checked")
    if rows < 60:
        fail(f"only {rows} rows")
    if failures:
        print(f"{len(failures)} failures")
        sys.exit(1)
    print("all exit-status rows passed")


main()
