#!/usr/bin/python3
"""Every list of node types outside the library agrees with its registry.

usage: test_registry.py BLENDTOOL SOURCE_DIR

The library's family registry (libblend/src/operators/families.def) is read
as `blendtool info --families --json`, and each hand-kept list is compared
with it:
- the JSON Schema (docs/libblend-scene.schema.json): one definition per
  type and convention it works in (none for the other), the same keys, set
  operations, argument counts, parameter ranges and defaults, and the node
  enums of each convention;
- the Blender add-on: props.py's primitive and blend lists (split by
  convention as the registry splits them) and the r / p / m / n property
  limits inside the registry's ranges; tree.py's keys per blend (only keys
  the node takes, the required parameters written, "op" as the row's set
  operations allow), and its VALUE_BLIND (the blends that use only their
  arguments' zero sets, where an m below has no effect);
- the fuzz dictionary (tests/fuzz/scene.dict): every type and key;
- the human form of `info --families` names every type.
Fails with one line per disagreement.
"""
import ast
import json
import os
import subprocess
import sys

blendtool, src = sys.argv[1], sys.argv[2]
failures = []


def fail(msg):
    failures.append(msg)


r = subprocess.run([blendtool, "info", "--families", "--json"], capture_output=True, text=True)
if r.returncode != 0:
    sys.exit("test_registry: blendtool info --families --json exited %d: %s" %
             (r.returncode, r.stderr))
reg = json.loads(r.stdout)
common = reg["common_keys"]
ops_rows = reg["operators"]
prims = reg["primitives"]
if len(ops_rows) < 16 or len(prims) < 9:
    sys.exit("test_registry: the registry lists %d operators, %d primitives" %
             (len(ops_rows), len(prims)))
types = [p["type"] for p in prims] + [o["type"] for o in ops_rows]

# ---- the JSON Schema ----
schema = json.load(open(os.path.join(src, "docs", "libblend-scene.schema.json")))
defs = schema["$defs"]


def number_range(prop):
    """(minimum, exclusive, maximum) of a number schema (the number branch of a oneOf)."""
    if "oneOf" in prop:
        prop = next(b for b in prop["oneOf"] if b.get("type") == "number")
    if "exclusiveMinimum" in prop:
        return prop["exclusiveMinimum"], True, prop.get("maximum")
    return prop.get("minimum"), False, prop.get("maximum")


def check_node_def(conv, row, is_prim):
    name = "%s_%s" % (conv, row["type"])
    d = defs.get(name)
    if d is None:
        fail("schema: no $defs/%s for %s in the %s convention" % (name, row["type"], conv))
        return
    props = d.get("properties", {})
    want = set(row["keys"]) | set(common) | set(row.get("soft_keys", []) if conv == "soft" else [])
    if set(props) != want:
        fail("schema: %s keys %s, registry %s" % (name, sorted(props), sorted(want)))
    if props.get("type", {}).get("const") != row["type"]:
        fail("schema: %s type const %r" % (name, props.get("type")))
    if d.get("additionalProperties") is not False:
        fail("schema: %s allows other keys" % name)
    if is_prim:
        return
    if row["ops"]:
        if props.get("op", {}).get("enum") != row["ops"]:
            fail("schema: %s op %r, registry %r" % (name, props.get("op"), row["ops"]))
    elif "op" in props:
        fail("schema: %s takes op, the registry none" % name)
    args = props.get("args", {})
    if (args.get("minItems"), args.get("maxItems")) != (row["min_args"], row["max_args"]):
        fail("schema: %s args %s..%s, registry %d..%d" % (name, args.get("minItems"),
                                                          args.get("maxItems"), row["min_args"],
                                                          row["max_args"]))
    required = set(d.get("required", []))
    for p in row["parameters"]:
        key = p["key"]
        if key not in props:
            fail("schema: %s has no %s" % (name, key))
            continue
        if p["required"] != (key in required):
            fail("schema: %s.%s required %s, registry %s" % (name, key, key in required,
                                                             p["required"]))
        if p["per_argument"]:
            lo, excl = (p["exclusive_minimum"], True) if "exclusive_minimum" in p else \
                (p["minimum"], False)
            got = number_range(props[key])
            if got != (lo, excl, p["maximum"]):
                fail("schema: %s.%s range %s, registry %s" % (name, key, got,
                                                             (lo, excl, p["maximum"])))
            arr = next((b for b in props[key].get("oneOf", []) if b.get("type") == "array"), None)
            if not arr or arr.get("maxItems") != row["max_args"] or \
                    (row["min_args"] == row["max_args"] and arr.get("minItems") != row["min_args"]):
                fail("schema: %s.%s: the array branch takes %s..%s, the node %d..%d arguments" %
                     (name, key, arr and arr.get("minItems"), arr and arr.get("maxItems"),
                      row["min_args"], row["max_args"]))
        elif not p["below_r1_r2"]:
            rng = p["range"][conv]
            got = number_range(props[key])
            if got != (rng["minimum"], False, rng["maximum"]):
                fail("schema: %s.%s range %s, registry %s" % (name, key, got, rng))


for p in prims:
    for conv in ("zero", "soft"):
        check_node_def(conv, p, True)
for o in ops_rows:
    for conv in ("zero", "soft"):
        if conv in o["conventions"]:
            check_node_def(conv, o, False)
        elif "%s_%s" % (conv, o["type"]) in defs:
            fail("schema: $defs/%s_%s exists, but %s is not a %s-convention operator" %
                 (conv, o["type"], o["type"], conv))


def enum_types(conv):
    """The node types a convention's node definition dispatches on."""
    found = set()

    def walk(x):
        if isinstance(x, dict):
            if "$ref" in x and x["$ref"].startswith("#/$defs/%s_" % conv):
                t = x["$ref"][len("#/$defs/%s_" % conv):]
                if t != "node":
                    found.add(t)
            for v in x.values():
                walk(v)
        elif isinstance(x, list):
            for v in x:
                walk(v)
    walk(defs["%s_node" % conv])
    return found


for conv in ("zero", "soft"):
    want = {p["type"] for p in prims} | {o["type"] for o in ops_rows if conv in o["conventions"]}
    got = enum_types(conv)
    if got != want:
        fail("schema: %s_node dispatches to %s; registry: %s" % (conv, sorted(got), sorted(want)))

# ---- the Blender add-on ----
addon = os.path.join(src, "blender_addon_c", "libblend_blender")


def literals(path):
    """Module-level list/dict literals, and the keyword arguments of annotated properties."""
    tree = ast.parse(open(path).read())
    lists, kw = {}, {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and len(node.targets) == 1 and \
                isinstance(node.targets[0], ast.Name):
            try:
                lists[node.targets[0].id] = ast.literal_eval(node.value)
            except ValueError:
                pass
        if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name) and \
                isinstance(node.annotation, ast.Call):
            args = {}
            for k in node.annotation.keywords:
                try:
                    args[k.arg] = ast.literal_eval(k.value)
                except ValueError:
                    pass
            kw[node.target.id] = args
    return lists, kw


props, props_kw = literals(os.path.join(addon, "props.py"))
ids = lambda items: [i[0] for i in items]  # noqa: E731
if ids(props["PRIMITIVES"]) != [p["type"] for p in prims]:
    fail("props.py: PRIMITIVES %s, registry %s" % (ids(props["PRIMITIVES"]),
                                                  [p["type"] for p in prims]))
by_conv = {"zero": [], "soft": [], "both": []}
for o in ops_rows:
    c = o["conventions"]
    by_conv["both" if len(c) == 2 else c[0]].append(o["type"])
addon_lists = {"zero": ids(props["BLENDS_ZERO"]), "soft": ids(props["BLENDS_SOFT"]),
               "both": ids(props["BLENDS_SHARP"]) + ids(props["BLENDS_BOTH"])}
for conv in by_conv:
    if sorted(addon_lists[conv]) != sorted(by_conv[conv]):
        fail("props.py: the %s-convention blends %s, registry %s" % (conv, addon_lists[conv],
                                                                    by_conv[conv]))


def param(typ, key):
    row = next(o for o in ops_rows if o["type"] == typ)
    return next(p for p in row["parameters"] if p["key"] == key)


def inside(prop_name, p):
    """An add-on property's hard limits lie inside the registry's range."""
    kw = props_kw.get(prop_name, {})
    lo = p.get("exclusive_minimum", p.get("minimum"))
    if "min" in kw and (kw["min"] < lo or (kw["min"] == lo and "exclusive_minimum" in p)):
        fail("props.py: %s min %g below the registry's %s" % (prop_name, kw["min"], p["allowed"]))
    if "min" not in kw:
        fail("props.py: %s has no min (the registry's %s)" % (prop_name, p["allowed"]))
    if "max" in kw and kw["max"] > p["maximum"]:
        fail("props.py: %s max %g above the registry's %s" % (prop_name, kw["max"], p["allowed"]))


for prop_name, typ, key in (("r", "displacement", "r"), ("arg_r", "displacement", "r"),
                            ("p", "displacement", "p"), ("arg_p", "displacement", "p"),
                            ("m", "displacement", "m"), ("arg_m", "displacement", "m")):
    inside(prop_name, param(typ, key))
n = param("ricci", "n")["range"]["soft"]
kw = props_kw.get("ricci_n", {})
if (kw.get("min"), kw.get("max")) != (n["minimum"], n["maximum"]):
    fail("props.py: ricci_n %s..%s, registry %s" % (kw.get("min"), kw.get("max"), n))

tree_lists, _ = literals(os.path.join(addon, "tree.py"))
blend_keys = tree_lists["BLEND_KEYS"]
local_extra = tuple(tree_lists["LOCAL_EXTRA"])
# the add-on's settings -> the scene keys they write
to_json = {"op": ("op",), "op2": ("op",), "r": ("r",), "p": ("p",), "m": ("m",),
           "conic_p": ("p",), "bulge": ("bulge",), "bulge_range": ("bulge",),
           "bounds": ("bounds",), "n": ("n",), "level": ("level",), "zero_scale": ("zero_scale",),
           "local": ("radius", "support", "support_factor", "exponent") + local_extra}
if sorted(blend_keys) != sorted(o["type"] for o in ops_rows):
    fail("tree.py: BLEND_KEYS names %s, registry %s" % (sorted(blend_keys),
                                                       sorted(o["type"] for o in ops_rows)))
for o in ops_rows:
    settings = blend_keys.get(o["type"], ())
    written = {"type", "args"}
    for s in settings:
        if s not in to_json:
            fail("tree.py: %s writes %r, which this test does not know" % (o["type"], s))
            continue
        written.update(to_json[s])
    extra = written - set(o["keys"])
    if extra:
        fail("tree.py: %s writes %s, which the node does not take" % (o["type"], sorted(extra)))
    for p in o["parameters"]:
        if p["required"] and p["key"] not in written:
            fail("tree.py: %s does not write its required %s" % (o["type"], p["key"]))
    want_op = {"": None, "union intersection": "op2",
               "union intersection difference": "op"}[" ".join(o["ops"])]
    got_op = [s for s in settings if s in ("op", "op2")]
    if got_op != ([want_op] if want_op else []):
        fail("tree.py: %s set operation setting %s, registry ops %s" % (o["type"], got_op,
                                                                        o["ops"]))

blind = sorted(o["type"] for o in ops_rows if not o["uses_argument_values"])
if sorted(tree_lists["VALUE_BLIND"]) != blind:
    fail("tree.py: VALUE_BLIND %s; registry (uses_argument_values false) %s" %
         (sorted(tree_lists["VALUE_BLIND"]), blind))
if blind != ["clean_union", "complement", "max", "min", "rfunction"]:
    fail("registry: the operators that use only their arguments' zero sets are %s" % blind)

# ---- the fuzz dictionary ----
words = set()
for line in open(os.path.join(src, "tests", "fuzz", "scene.dict")):
    line = line.strip()
    if line.startswith('"\\"') and line.endswith('\\""'):
        words.add(line[3:-3])
need = set(types) | set(common)
for row in prims + ops_rows:
    need.update(row["keys"])
    need.update(row.get("soft_keys", []))
for o in ops_rows:
    need.update(o["ops"])
missing = sorted(need - words)
if missing:
    fail("scene.dict: missing %s" % ", ".join(missing))

# ---- the human form ----
r = subprocess.run([blendtool, "info", "--families"], capture_output=True, text=True)
for t in types:
    if r.returncode != 0 or ("  %s " % t) not in r.stdout:
        fail("info --families: %s not listed" % t)
r = subprocess.run([blendtool, "info", "--families", "scenes/x.json"], capture_output=True,
                   text=True)
if r.returncode != 2 or "--families takes no scene" not in r.stderr:
    fail("info --families SCENE: exit %d, %s" % (r.returncode, r.stderr.strip()))

for f in failures:
    print("test_registry:", f)
if failures:
    sys.exit(1)
print("test_registry: %d primitives, %d operators; the schema, the add-on's lists and the fuzz "
      "dictionary agree" % (len(prims), len(ops_rows)))
