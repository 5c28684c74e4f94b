"""The gallery's field sections (docs/gallery/sections.json): each entry
is one `blendtool section` run, its arguments given as a list (never
through a shell); the scene path is relative to docs/gallery/.

usage: /usr/bin/python3 scripts/gallery_sections.py BLENDTOOL SOURCE_DIR OUT_DIR
Writes OUT_DIR/NAME.png for every entry; exit 1 when one fails."""
import json
import os
import subprocess
import sys


def entries(src):
    gal = os.path.join(src, "docs", "gallery")
    for e in json.load(open(os.path.join(gal, "sections.json"))):
        yield e["name"], os.path.normpath(os.path.join(gal, e["scene"])), e["args"]


def main():
    bt, src, out = sys.argv[1:4]
    os.makedirs(out, exist_ok=True)
    rc = 0
    for name, scene, args in entries(src):
        png = os.path.join(out, name + ".png")
        r = subprocess.run([bt, "section", scene, "-o", png, "--threads", "2"] + args)
        print("section: %s %s" % (png, "ok" if r.returncode == 0 else "FAILED"), flush=True)
        rc = rc or r.returncode
    sys.exit(1 if rc else 0)


if __name__ == "__main__":
    main()
