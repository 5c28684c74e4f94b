#!/usr/bin/python3
"""How a local blend's blending volume should reach POV-Ray: measured.

Two representations of the volume's field a = distance to the curve / R
(clamped at 1), for scenes with one local_union:
- "unrolled": what blendtool pov writes, the curve's segments as data in a
  tree of POV-Ray functions mirroring the evaluator's box hierarchy (lazy
  select skips boxes R or farther away);
- "DF3 N": a density file of a sampled on an N^3 grid over the volume's box
  (the curve's box grown by R), read back with trilinear interpolation.
The DF3 variants are made from the exported .pov: its segments are read
back and a is computed on the grid with numpy.

For each: the largest difference of POV-Ray's field from libblend's
evaluator (blendtool eval) at 2000 points within R of the curve (half of
them) and in the bounds, and povray's user CPU seconds for a 640 x 480
render (one thread), with the plain clean union of the same scene (no
volume at all) as the baseline in the same run.

usage: bench_pov_local.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import os
import re
import resource
import struct
import subprocess
import sys

import numpy as np

bt, src, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
src = os.path.abspath(src)
bt = os.path.abspath(bt) if os.sep in bt else bt
work = os.path.abspath(work)
inc = os.path.join(src, "povray_include")
SCENES = ["bernhardt-compare-local.json", "bernhardt-drop-08.json"]
NUM = r"(-?[0-9.]+(?:e[+-]?[0-9]+)?)"


def povray(pov, w, h, out=None):
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
    args = ["povray", "+I" + pov, "+L" + inc, "+W%d" % w, "+H%d" % h, "-D", "-V", "+WT1"]
    args += ["+O" + out, "+FN"] if out else ["-F"]
    r = subprocess.run(args, capture_output=True, text=True, cwd=work)
    if r.returncode != 0:
        raise SystemExit("povray failed on %s:\n%s" % (pov, r.stderr[-2000:]))
    return resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before


def segments(text):
    """the exported curve: segment starts A, directions D; R from the leaves"""
    segs = re.findall(r"lb_seg2\(x, y, z, " + ", ".join([NUM] * 7) + r"\)", text)
    R = float(re.search(r"\)\) / " + NUM + r"\), 1\) \}", text).group(1))
    S = np.array(segs, dtype=float)
    return S[:, 0:3], S[:, 3:6], R


def field_a(P, A, D, R):
    """min over segments of distance / R, clamped at 1 (numpy, chunked)"""
    out = np.empty(len(P))
    ll = np.maximum((D * D).sum(1), 1e-300)
    for i in range(0, len(P), 20000):
        X = P[i:i + 20000, None, :] - A[None, :, :]
        t = np.clip((X * D[None]).sum(2) / ll[None], 0.0, 1.0)
        d2 = ((X - t[..., None] * D[None]) ** 2).sum(2).min(1)
        out[i:i + 20000] = np.minimum(1.0, np.sqrt(d2) / R)
    return out


def write_df3(path, vol):  # vol[z, y, x] in [0, 1], 16 bits, big-endian
    nz, ny, nx = vol.shape
    with open(path, "wb") as f:
        f.write(struct.pack(">HHH", nx, ny, nz))
        f.write(np.round(np.clip(vol, 0, 1) * 65535).astype(">u2").tobytes())


def df3_variant(text, A, D, R, n, name):
    pts = np.concatenate([A, A + D])
    lo, hi = pts.min(0) - R, pts.max(0) + R
    h = (hi - lo) / (n - 1)
    g = [lo[d] + h[d] * np.arange(n) for d in range(3)]
    Z, Y, X = np.meshgrid(g[2], g[1], g[0], indexing="ij")
    P = np.stack([X.ravel(), Y.ravel(), Z.ravel()], 1)
    write_df3(os.path.join(work, name + ".df3"), field_a(P, A, D, R).reshape(n, n, n))
    S = n * h
    decl = ("#declare LBdf = function { pattern { density_file df3 \"%s.df3\" interpolate 1 } }\n"
            "#declare LBda = function(x, y, z) { select(max(%r - x, x - %r, %r - y, y - %r, "
            "%r - z, z - %r), LBdf((x - %r) / %r, (y - %r) / %r, (z - %r) / %r), 1) }\n"
            % (name, lo[0], hi[0], lo[1], hi[1], lo[2], hi[2], lo[0], S[0], lo[1], S[1], lo[2],
               S[2]))
    # the component's distance call in the chain becomes the DF3 lookup
    new, k = re.subn(r"LBv(\d+)_(\d+)\(x, y, z\)\) \}", "LBda(x, y, z)) }", text)
    if k != 1:
        raise SystemExit("expected one blending volume in the export")
    i = new.index("#declare LBk")
    return new[:i] + decl + new[i:]


def agreement(text, name, P, expect):
    pov = os.path.join(work, name + "-agree.pov")
    body = text.split("\nglobal_settings")[0]
    with open(pov, "w") as f:
        f.write(body + "\n#fopen FO \"%s.txt\" write\n" % name)
        for p in P:
            f.write("#write (FO, str(LB_Field(%r, %r, %r), 0, 17), \"\\n\")\n" % tuple(p))
        f.write("#fclose FO\n")
    povray(pov, 1, 1)
    got = np.loadtxt(os.path.join(work, name + ".txt"))
    return float(np.abs(got - expect).max())


print("| scene | blending volume in POV-Ray | max abs difference from libblend | "
      "render CPU s (640 x 480, 1 thread) | vs the clean union |")
print("|---|---|---|---|---|")
rng = np.random.default_rng(5)
for scene in SCENES:
    path = os.path.join(src, "scenes", scene)
    base = os.path.join(work, scene[:-5])
    subprocess.run([bt, "pov", path, "-o", base + ".pov"], check=True)
    text = open(base + ".pov").read()
    A, D, R = segments(text)
    # points: half near the curve (within R), half in the bounds
    lo = np.array([float(v) for v in re.search(r"box \{ <" + ", ".join([NUM] * 3), text).groups()])
    hi = np.array([float(v) for v in re.search(r"box \{ <[^>]*>, <" + ", ".join([NUM] * 3),
                                                  text).groups()])
    near = A[rng.integers(0, len(A), 1000)] + rng.uniform(-R, R, (1000, 3))
    P = np.concatenate([near, rng.uniform(lo, hi, (1000, 3))])
    r = subprocess.run([bt, "eval", path, "--threads", "1"], input="\n".join(
        "%r %r %r" % tuple(p) for p in P) + "\n", capture_output=True, text=True, check=True)
    expect = np.array([float(l.split()[0]) for l in r.stdout.splitlines()])
    # the baseline: the same pair under the plain clean union
    clean = re.sub(r"LBk(\d+)_0\(x, y, z, lbLg1, lbLg2, 1, 0, 0, (lb_clean_uc\([^)]*\))\)",
                   r"\2", text)
    open(base + "-clean.pov", "w").write(clean)
    t0 = povray(base + "-clean.pov", 640, 480, base + "-clean.png")
    rows = [("unrolled segments (%d), blendtool pov" % len(A), text)]
    for n in (32, 64, 128):
        rows.append(("DF3 %d^3, 16 bit, trilinear" % n,
                     df3_variant(text, A, D, R, n, "%s-df3-%d" % (scene[:-5], n))))
    for label, t in rows:
        name = re.sub(r"[^a-z0-9]+", "-", (scene[:-5] + "-" + label).lower())[:60]
        pov = os.path.join(work, name + ".pov")
        open(pov, "w").write(t)
        err = agreement(t, name, P, expect)
        cpu = povray(pov, 640, 480, os.path.join(work, name + ".png"))
        print("| %s | %s | %.2g | %.2f | %.2fx |" % (scene, label, err, cpu, cpu / t0))
    print("| %s | none (clean union) | - | %.2f | 1.00x |" % (scene, t0))
