"""The ctypes binding's structs match the C library's, field by field:

    python3 test_abi_layout.py ABI_LAYOUT ADDON_DIR

ABI_LAYOUT (abi_layout.c, built with the library's headers) prints each
public struct's size and field offsets as the C compiler lays them out;
every ctypes Structure in binding.py that mirrors one must have the same
size, the same fields in the same order and the same offsets, and every C
field must be in the binding. A field added to a struct in C alone would
make the library read or write past the binding's buffer (lb_mesh_options
and lb_pov_options gained fields on 2026-12-04)."""
import ctypes
import json
import subprocess
import sys

LAYOUT, ADDON = sys.argv[1:3]
sys.path.insert(0, ADDON)
import binding  # noqa: E402

c = json.loads(subprocess.run([LAYOUT], check=True, capture_output=True, text=True).stdout)
bad = []
structs = {n: v for n, v in vars(binding).items()
           if isinstance(v, type) and issubclass(v, ctypes.Structure)}
for name, cls in sorted(structs.items()):
    if name not in c:
        bad.append("%s: a ctypes Structure with no C layout in abi_layout.c" % name)
for name, lay in sorted(c.items()):
    cls = structs.get(name)
    before = len(bad)
    if cls is None:
        bad.append("%s: no such Structure in binding.py" % name)
        continue
    py = [f[0] for f in cls._fields_]
    cf = sorted(lay["fields"], key=lambda f: lay["fields"][f])
    if py != cf:
        bad.append("%s: fields %s in the binding, %s in C" % (name, py, cf))
    for f in py:
        if f in lay["fields"] and getattr(cls, f).offset != lay["fields"][f]:
            bad.append("%s.%s: offset %d in the binding, %d in C" %
                       (name, f, getattr(cls, f).offset, lay["fields"][f]))
    if ctypes.sizeof(cls) != lay["size"]:
        bad.append("%s: %d bytes in the binding, %d in C" % (name, ctypes.sizeof(cls),
                                                            lay["size"]))
    print("%-12s %3d bytes, %2d fields: %s" % (name, lay["size"], len(cf),
                                               "same" if len(bad) == before else "differs"))
for b in bad:
    print("FAIL " + b)
sys.exit(1 if bad else 0)
