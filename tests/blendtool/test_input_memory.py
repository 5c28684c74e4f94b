#!/usr/bin/python3
"""Input amplification: the peak memory of `blendtool validate` stays within
the documented multiple of the scene file's size (docs/scene-format.md,
"Limits"), for accepted scenes at the node limit and for files that cannot
be scenes. A file of nothing but arrays (the 63 MB of [] that once took
40 s and 4.5 GB) is refused by the pre-scan, before any parser builds a
tree: in well under a second, with the file itself as the peak.

usage: test_input_memory.py BLENDTOOL WORK_DIR
"""
import json
import os
import shutil
import subprocess
import sys
import time

BT, WORK = sys.argv[1:3]
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
failures = []
MULTIPLE = 48          # docs/scene-format.md: peak <= 48 x the file + BASE
BASE = 16 * 1024       # KiB: the process itself


def peak(path):
    """(exit status, peak RSS in KiB, seconds) of validate on path, measured by
    GNU time around blendtool alone (this process's memory, copied by a fork,
    must not count)"""
    t = time.monotonic()
    r = subprocess.run(["/usr/bin/time", "-f", "PEAK %M", BT, "validate", "--quiet", path],
                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    kib = [int(l.split()[1]) for l in r.stderr.splitlines() if l.startswith("PEAK ")]
    return r.returncode, kib[-1] if kib else 1 << 40, time.monotonic() - t


def case(name, text, want_rc, max_seconds=None, multiple=MULTIPLE):
    path = os.path.join(WORK, name + ".json")
    with open(path, "w") as f:
        f.write(text)
    size_kib = os.path.getsize(path) / 1024
    rc, kib, sec = peak(path)
    ratio = kib / size_kib
    print("%-28s %8.0f KiB file, exit %d, peak %8d KiB (%.1fx), %.2f s" % (
        name, size_kib, rc, kib, ratio, sec))
    if rc != want_rc:
        failures.append("%s: exit %d, want %d" % (name, rc, want_rc))
    if kib > multiple * size_kib + BASE:
        failures.append("%s: peak %d KiB over %d x the file + %d" % (name, kib, multiple, BASE))
    if max_seconds and sec > max_seconds:
        failures.append("%s: %.1f s, want under %g" % (name, sec, max_seconds))
    os.remove(path)


HEAD = '{"format": "libblend-scene", "version": 1, "convention": "zero", '
sph = '{"type": "sphere", "center": [%d, 0, 0], "radius": 1}'
# accepted: a flat union at the argument limit; nested defs near the node limit
case("65535 spheres", HEAD + '"root": {"type": "min", "args": [' +
     ", ".join(sph % i for i in range(65535)) + "]}}", 0)
defs = {"d%d" % i: {"type": "min", "args": [json.loads(sph % j) for j in range(1000)]}
        for i in range(99)}
case("99 defs of 1000 spheres", HEAD + '"defs": ' + json.dumps(defs) + ', "root": {"type": "min", '
     '"args": [' + ", ".join('{"ref": "d%d"}' % i for i in range(99)) + "]}}", 0)
# the densest JSON per node: compact spheres, and refs with a transform each
# (a group node, its transform and an instruction for 35 bytes of text)
case("65535 compact spheres", HEAD.replace(" ", "") + '"root":{"type":"min","args":[' +
     ",".join('{"type":"sphere","center":[%d,0,0],"radius":1}' % (i % 10) for i in range(65535)) +
     "]}}", 0)
case("65535 refs with translate", HEAD.replace(" ", "") +
     '"defs":{"s":{"type":"sphere","center":[0,0,0],"radius":1}},"root":{"type":"min","args":[' +
     ",".join('{"ref":"s","translate":[%d,0,0]}' % i for i in range(65535)) + "]}}", 0)
# refused by the pre-scan: arrays, objects, values beyond any scene
case("63 MB of []", HEAD + '"root": ' + sph % 0 + ', "x": [' + ",".join(["[]"] * 21000000) + "]}",
     2, max_seconds=2.0, multiple=2)
case("objects", HEAD + '"root": ' + sph % 0 + ', "x": [' + ",".join(["{}"] * 600000) + "]}", 2,
     max_seconds=2.0, multiple=2)
case("numbers", HEAD + '"root": ' + sph % 0 + ', "x": [' + ",".join(["1"] * 5000000) + "]}", 2,
     max_seconds=2.0, multiple=2)
# an array longer than any scene's (65535): refused by the pre-scan too
case("a long r list", HEAD + '"root": {"type": "displacement", "op": "union", "r": [' +
     ",".join(["0.5"] * 3000000) + '], "args": [' + sph % 0 + ", " + sph % 1 + "]}}", 2,
     max_seconds=2.0, multiple=2)
print("%d failures" % len(failures))
sys.exit(1 if failures else 0)
