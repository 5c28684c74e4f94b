"""The little harness the Python tests outside Blender share: the command
line (BLENDTOOL SOURCE_DIR WORK_DIR), fail() and check() that record a
failure and go on (the list is `failures`), and finish() that prints the
summary and sets the exit status. A test in a folder below tests/ puts
tests/ on sys.path first."""
import os
import sys

failures = []


def args():
    """(BLENDTOOL, SOURCE_DIR, WORK_DIR) from the command line; WORK_DIR is made."""
    blendtool, src, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    return blendtool, src, work


def fail(what):
    failures.append(what)
    print("FAIL: " + what)


def check(cond, what):
    """records what as a failure unless cond; returns cond"""
    if not cond:
        fail(what)
    return cond


def finish(name, ok_message):
    if failures:
        print("%s: %d failures" % (name, len(failures)))
        sys.exit(1)
    print("%s: %s" % (name, ok_message))


def read_ppm(path):
    """Binary PPM (P6, as POV-Ray and oiiotool write it): header tokens with #
    comments, then samples; (width, height, [[r, g, b] in 0..1 per pixel])."""
    data = open(path, "rb").read()
    parts, pos = [], 0
    while len(parts) < 4:  # magic, width, height, maxval
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        parts.append(data[pos:end])
        pos = end
    pos += 1
    w, h, mx = int(parts[1]), int(parts[2]), int(parts[3])
    step = 2 if mx > 255 else 1
    px = data[pos:]
    vals = [int.from_bytes(px[i:i + step], "big") / mx for i in range(0, len(px), step)]
    return w, h, [vals[i:i + 3] for i in range(0, len(vals), 3)]
