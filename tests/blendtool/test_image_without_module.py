#!/usr/bin/python3
"""blendtool on a machine without its image module (OpenImageIO), as on a
bare farm node: a copy of the executable in a folder without
liblbimageio.so. POV-Ray then writes the final PNG itself and blendtool
replaces its time stamp and text chunks with the libblend metadata
(png_direct.c). Checked here against an independent reading of the PNG
(Python's zlib for every CRC and for the pixels) and against the render of
the same scene through the module (the normal build): the same pixels.
OpenEXR, contact sheets and `section` are refused with nothing written.

usage: test_image_without_module.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import json
import os
import shutil
import struct
import subprocess
import sys
import zlib

BT, SRC, WORK = (os.path.abspath(a) for a in sys.argv[1:4])
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(os.path.join(WORK, "bare"))
BARE = os.path.join(WORK, "bare", "blendtool")
shutil.copy2(BT, BARE)  # libblend.so through its absolute build-tree RUNPATH
SCENE = os.path.join(SRC, "scenes", "default.json")
ENV = dict(os.environ, LIBBLEND_POVRAY_INCLUDE=os.path.join(SRC, "povray_include"))
ENV.pop("LIBBLEND_IMAGEIO", None)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import fail, failures  # noqa: E402


def run(exe, *args):
    return subprocess.run([exe, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=ENV,
                          cwd=WORK, timeout=300)


def chunks(path):
    """(type, data) of every chunk; fails the test on a bad signature or CRC"""
    b = open(path, "rb").read()
    if b[:8] != b"\x89PNG\r\n\x1a\n":
        fail(f"{path}: no PNG signature")
        return []
    out, at = [], 8
    while at < len(b):
        (n,) = struct.unpack(">I", b[at:at + 4])
        t, d = b[at + 4:at + 8], b[at + 8:at + 8 + n]
        (crc,) = struct.unpack(">I", b[at + 8 + n:at + 12 + n])
        if zlib.crc32(t + d) != crc:
            fail(f"{path}: chunk {t!r} fails its CRC")
        out.append((t.decode("latin-1"), d))
        at += 12 + n
    return out


def pixels(cs):
    """the unfiltered rows (bytes) of a non-interlaced PNG"""
    w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", cs[0][1])
    bpp = {2: 3, 6: 4}[ctype] * depth // 8
    raw = zlib.decompress(b"".join(d for t, d in cs if t == "IDAT"))
    stride, rows, prev, at = w * bpp, [], bytearray(w * bpp), 0
    for _ in range(h):
        f, line = raw[at], bytearray(raw[at + 1:at + 1 + stride])
        at += 1 + stride
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            up = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + up) & 255
            elif f == 3:
                line[i] = (line[i] + (a + up) // 2) & 255
            elif f == 4:
                p = a + up - c
                pa, pb, pc = abs(p - a), abs(p - up), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else up if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    return (w, h, depth, ctype, interlace), b"".join(rows)


def render(exe, out, *extra):
    return run(exe, "render", SCENE, "-o", out, "--width", "40", "--height", "30", "--threads",
               "1", "--quality", "9", *extra)


# 8-bit RGB, the default: POV-Ray's PNG, its time stamp replaced
direct = os.path.join(WORK, "direct.png")
r = render(BARE, direct)
err = r.stderr.decode(errors="replace")
if r.returncode != 0:
    fail(f"render without the module: exit {r.returncode}: {err[-400:]}")
elif "note: cannot load the image module" not in err or "POV-Ray writes the PNG itself" not in err:
    fail(f"no note that POV-Ray's PNG is written: {err[-400:]!r}")
cs = chunks(direct) if os.path.exists(direct) else []
types = [t for t, _ in cs]
if cs:
    if types[0] != "IHDR" or types[-1] != "IEND":
        fail(f"chunk order {types}")
    if "tIME" in types:
        fail("POV-Ray's tIME chunk is still there")
    texts = {d.split(b"\0", 1)[0].decode(): d.split(b"\0", 1)[1] for t, d in cs if t == "tEXt"}
    if set(texts) != {"libblend:scene_hash", "libblend:version", "libblend:render",
                      "libblend:parameters"}:
        fail(f"text chunks {sorted(texts)}")
    if texts.get("libblend:render") != b"40x30 quality 9":
        fail(f"libblend:render is {texts.get('libblend:render')!r}")
    if max(i for i, t in enumerate(types) if t == "tEXt") > types.index("IDAT"):
        fail(f"metadata after the image data: {types}")
    head, px = pixels(cs)
    if head != (40, 30, 8, 2, 0):
        fail(f"IHDR {head}, want 40x30 8-bit RGB")
    # the same pixels as the module's render of the same scene
    via = os.path.join(WORK, "module.png")
    if render(BT, via).returncode != 0:
        fail("render through the module failed")
    else:
        head2, px2 = pixels(chunks(via))
        if (head2, px2) != (head, px):
            diff = max(abs(a - b) for a, b in zip(px, px2)) if len(px) == len(px2) else "sizes"
            fail(f"pixels differ from the module's render ({head2} vs {head}, max {diff})")
    # the same bytes on a second run
    again = os.path.join(WORK, "again.png")
    render(BARE, again)
    if not os.path.exists(again) or open(again, "rb").read() != open(direct, "rb").read():
        fail("a second render gave other bytes")

# 16 bits with alpha: POV-Ray writes exactly that
deep = os.path.join(WORK, "deep.png")
if render(BARE, deep, "--bits", "16", "--alpha").returncode != 0:
    fail("16-bit RGBA render without the module failed")
else:
    head, px = pixels(chunks(deep))
    if head[2:4] != (16, 6):
        fail(f"--bits 16 --alpha wrote depth {head[2]} colour type {head[3]}, want 16 and 6")
    via = os.path.join(WORK, "module16.png")
    if render(BT, via, "--bits", "16", "--alpha").returncode != 0:
        fail("16-bit RGBA render through the module failed")
    elif pixels(chunks(via)) != (head, px):
        fail("16-bit RGBA pixels differ from the module's render")

# OpenEXR: refused, exit 1, one message naming the fix, nothing written
exr = os.path.join(WORK, "x.exr")
r = render(BARE, exr)
err = r.stderr.decode(errors="replace")
if r.returncode != 1 or "OpenEXR needs the image module" not in err or "x.exr" not in err:
    fail(f"EXR without the module: exit {r.returncode}, {err[-300:]!r}")
if os.path.exists(exr):
    fail("the refused EXR render wrote a file")
# a bad scene is a bad scene whatever the output: exit 2 naming it, before
# the image module is asked about
bad = os.path.join(WORK, "bad.json")
with open(bad, "w") as f:
    f.write('{"format": "libblend-scene", "version": 1, "convention": "zero", "root": {"type": '
            '"sphere", "radius": -1}}')
r = run(BARE, "render", bad, "-o", exr, "--width", "40", "--height", "30")
err = r.stderr.decode(errors="replace")
if r.returncode != 2 or "bad.json" not in err or "radius" not in err:
    fail(f"a bad scene with an EXR output without the module: exit {r.returncode}, {err[-300:]!r}")
if os.path.exists(exr):
    fail("the bad scene's EXR render wrote a file")

# section draws through the module only: exit 1 naming it, nothing written
sec = os.path.join(WORK, "section.png")
r = run(BARE, "section", SCENE, "-o", sec, "--plane", "z=0", "--width", "64", "--height", "64")
err = r.stderr.decode(errors="replace")
if r.returncode != 1 or "cannot load the image module" not in err:
    fail(f"section without the module: exit {r.returncode}, {err[-300:]!r}")
if os.path.exists(sec):
    fail("the refused section wrote a file")

# batch: PNG images work; a contact sheet is refused before any folder exists
for sheet in (False, True):
    out = os.path.join(WORK, f"batch-{int(sheet)}")
    job = {"format": "libblend-job", "version": 1, "name": "j", "scene": SCENE,
           "sweep": [{"path": "root.args[1].e1", "values": [0.3, 0.4]}],
           "outputs": {"image": {"format": "png", "width": 24, "height": 18}},
           "output_dir": out}
    if sheet:
        job["outputs"]["contact_sheet"] = {"columns": 2}
    jf = os.path.join(WORK, f"job-{int(sheet)}.json")
    json.dump(job, open(jf, "w"))
    r = run(BARE, "batch", jf, "--threads", "1")
    err = r.stderr.decode(errors="replace")
    if not sheet:
        pngs = sorted(f for f in os.listdir(out) if f.endswith(".png")) if os.path.isdir(out) else []
        if r.returncode != 0 or len(pngs) != 2:
            fail(f"batch without the module: exit {r.returncode}, images {pngs}: {err[-300:]!r}")
        for p in pngs:
            t = [c for c, _ in chunks(os.path.join(out, p))]
            if "tIME" in t or t.count("tEXt") != 5:
                fail(f"batch image {p}: chunks {t}")
    else:
        if r.returncode != 1 or "contact sheet needs the image module" not in err:
            fail(f"batch with a sheet without the module: exit {r.returncode}: {err[-300:]!r}")
        if os.path.exists(out):
            fail("the refused batch created its output folder")

if failures:
    print(f"{len(failures)} failures")
    sys.exit(1)
print("test_image_without_module: OK")
