#!/usr/bin/python3
"""The scripting reference of blender_addon_c/README.md names everything a
script can use: every operator of ops.py (as `libblend.<name>` in the
operator table, with each of its properties in its row), every setting of
props.py's LB_ObjectSettings (as `<name>` in the settings table) and every
primitive type of props.PRIMITIVES (in add_primitive's row). Read from the
add-on's source with ast (no Blender needed), so a new operator, property or
setting cannot be left undocumented. Also: the table names nothing that does
not exist.

usage: test_addon_reference.py SOURCE_DIR
"""
import ast
import os
import re
import sys

SRC = sys.argv[1]
ADDON = os.path.join(SRC, "blender_addon_c", "libblend_blender")
readme = open(os.path.join(SRC, "blender_addon_c", "README.md")).read()
failures = []


def fail(msg):
    failures.append(msg)
    print("FAIL: " + msg)


section = readme[readme.index("### Scripting reference"):]
section = section[:section.index("\n## ")] if "\n## " in section else section
rows = {}
for line in section.splitlines():
    m = re.match(r"\| `libblend\.(\w+)` \|(.*)$", line)
    if m:
        rows[m.group(1)] = m.group(2)
settings_table = section[section.index("| on | settings |"):]


def hidden(call):
    for k in call.keywords:
        if k.arg == "options" and "HIDDEN" in ast.unparse(k.value):
            return True
    return False


def annotated(cls):
    """property names declared as `name: XxxProperty(...)` in a class body,
    except those hidden from the user (options={"HIDDEN"})"""
    out = []
    for n in cls.body:
        if isinstance(n, ast.AnnAssign) and isinstance(n.target, ast.Name) and \
                isinstance(n.annotation, ast.Call) and \
                getattr(n.annotation.func, "id", "").endswith("Property") and \
                not hidden(n.annotation):
            out.append(n.target.id)
    return out


ops_tree = ast.parse(open(os.path.join(ADDON, "ops.py")).read())
classes = {c.name: c for c in ops_tree.body if isinstance(c, ast.ClassDef)}
ops = {}
for c in classes.values():
    idname = None
    for n in c.body:
        if isinstance(n, ast.Assign) and getattr(n.targets[0], "id", None) == "bl_idname":
            idname = n.value.value
    if not idname:
        continue
    props = annotated(c)
    for b in c.bases:  # properties declared on a shared base class of the add-on
        if isinstance(b, ast.Name) and b.id in classes:
            props += [p for p in annotated(classes[b.id]) if p not in props]
    ops[idname.split(".", 1)[1]] = props
    if any(getattr(b, "id", "") == "ImportHelper" or getattr(b, "id", "") == "ExportHelper"
           for b in c.bases):
        ops[idname.split(".", 1)[1]].append("filepath")
for op, props in sorted(ops.items()):
    if op not in rows:
        fail("README: the operator libblend.%s is not in the scripting reference" % op)
        continue
    for p in props:
        if "`%s`" % p not in rows[op]:
            fail("README: libblend.%s's property %s is not in its row" % (op, p))
for op in rows:
    if op not in ops:
        fail("README: the reference names libblend.%s, which ops.py does not define" % op)
if len(ops) < 14:
    fail("only %d operators found in ops.py: the parse went wrong" % len(ops))

props_tree = ast.parse(open(os.path.join(ADDON, "props.py")).read())
settings = next(c for c in props_tree.body
                if isinstance(c, ast.ClassDef) and c.name == "LB_ObjectSettings")
names = annotated(settings)
if len(names) < 60:
    fail("only %d settings found in LB_ObjectSettings: the parse went wrong" % len(names))
for name in names:
    if "`%s`" % name not in settings_table:
        fail("README: the setting obj.libblend.%s is not in the settings table" % name)
for prim in next(ast.literal_eval(n.value) for n in props_tree.body
                 if isinstance(n, ast.Assign) and getattr(n.targets[0], "id", "") == "PRIMITIVES"):
    if "'%s'" % prim[0] not in rows.get("add_primitive", ""):
        fail("README: the primitive type %r is not in add_primitive's row" % prim[0])
if failures:
    sys.exit(1)
print("test_addon_reference: %d operators, %d settings documented" % (len(ops), len(names)))
