#!/usr/bin/python3
"""The JSON Schema in docs/ agrees with libblend's own parser.

usage: test_schema.py BLENDTOOL SOURCE_DIR

- the schema is a valid Draft 2020-12 schema;
- every scene shipped in scenes/ and tests/data/scenes/ passes both the schema
  and `blendtool validate`;
- the node kinds the schema names are exactly the kinds the library names in
  its "unknown node type" message;
- mutations that break a scene (unknown key, unknown kind, wrong-typed or
  out-of-range value, an operator of the other convention, a kernel in a zero
  scene) are rejected by both.
"""
import copy
import glob
import json
import os
import re
import subprocess
import sys
import tempfile

import jsonschema

blendtool, src = sys.argv[1], sys.argv[2]
schema = json.load(open(os.path.join(src, "docs", "libblend-scene.schema.json")))
jsonschema.Draft202012Validator.check_schema(schema)


def items_once_per_object(validator, items, instance, schema):
    """The 2020-12 `items` keyword, validating each distinct Python object once.

    The arity cases below hold up to 65,536 references to one sphere dict;
    an array item's verdict depends only on its value and the subschema, so
    the same object need not be walked 65,536 times (that took 70 of the
    test's 84 s). Lists loaded from JSON hold distinct objects and are
    validated item by item as before."""
    if not validator.is_type(instance, "array"):
        return
    prefix = len(schema.get("prefixItems", []))
    found = {}
    for index, item in enumerate(instance[prefix:], start=prefix):
        if id(item) not in found:
            found[id(item)] = list(validator.descend(item, items, path=index))
        yield from found[id(item)]


validator = jsonschema.validators.extend(
    jsonschema.Draft202012Validator, {"items": items_once_per_object})(schema)
failures = []


pending = []  # (scene, what to do with the library's verdict)


def library_then(doc, then):
    """Queue a scene for `blendtool validate`; then(ok, message) runs once
    every queued scene has been validated (run_library below)."""
    pending.append((doc, then))


def run_library():
    """Validate the queued scenes a few hundred per blendtool process (one
    process per scene took most of the test's time under ASan), attributing
    each stderr message to its file by name."""
    with tempfile.TemporaryDirectory() as tmp:
        names = []
        for i, (doc, _) in enumerate(pending):
            names.append(os.path.join(tmp, "s%05d.json" % i))
            with open(names[-1], "w") as f:
                json.dump(doc, f)
        said = {name: [] for name in names}
        pattern = re.compile(r"blendtool validate: (%s/s\d{5}\.json):" % re.escape(tmp))
        for start in range(0, len(names), 300):
            chunk = names[start:start + 300]
            r = subprocess.run([blendtool, "validate", "--quiet"] + chunk, capture_output=True, text=True)
            for line in r.stderr.splitlines():
                m = pattern.match(line)
                if m and m.group(1) in said:
                    said[m.group(1)].append(line)
                else:
                    failures.append("blendtool validate: a message naming no scene: %s" % line)
            if r.returncode not in (0, 2) or (r.returncode == 0) != all(not said[n] for n in chunk):
                failures.append("blendtool validate exited %d against its messages: %s" % (
                    r.returncode, r.stderr[-2000:]))
        for name, (_, then) in zip(names, pending):
            then(not said[name], "\n".join(said[name]))
    pending.clear()


def schema_accepts(doc):
    return validator.is_valid(doc)


def nodes(doc):
    """Every node object of a scene (root, defs, args and bounds, recursively)."""
    todo = [doc["root"]] + list(doc.get("defs", {}).values())
    while todo:
        n = todo.pop()
        yield n
        todo.extend(n.get("args", []))
        todo.extend(n.get("bounds", []))


scenes = sorted(glob.glob(os.path.join(src, "scenes", "*.json")) +
                glob.glob(os.path.join(src, "tests", "data", "scenes", "*.json")))
if len(scenes) < 10:
    failures.append("only %d scenes found under %s" % (len(scenes), src))
mutations = 0
for path in scenes:
    doc = json.load(open(path))

    def shipped(ok, msg, path=path):
        if not ok:
            failures.append("%s: blendtool rejects it: %s" % (path, msg))
    library_then(doc, shipped)
    errs = list(validator.iter_errors(doc))
    if errs:
        failures.append("%s: the schema rejects it: %s" % (path, errs[0].message[:300]))
    other = "soft" if doc["convention"] == "zero" else "zero"
    cases = []
    for i, n in enumerate(nodes(doc)):
        if "ref" in n:
            continue
        def mutate(fn, what, i=i):
            d = copy.deepcopy(doc)
            fn(list(nodes(d))[i])
            cases.append((what, d))
        mutate(lambda n: n.__setitem__("colour", 1), "unknown key on node %d" % i)
        mutate(lambda n: n.__setitem__("type", n["type"] + "x"), "unknown kind on node %d" % i)
        for key in ("radius", "r", "half_width", "minor_radius", "e1", "exponent"):
            if key in n:
                mutate(lambda n, key=key: n.__setitem__(key, "1"), "string %s on node %d" % (key, i))
                mutate(lambda n, key=key: n.__setitem__(key, -1), "negative %s on node %d" % (key, i))
        if "p" in n and n["type"] in ("displacement", "scale", "bounded", "soft_hyper"):
            mutate(lambda n: n.__setitem__("p", 1), "p = 1 on node %d" % i)
        if "args" in n:
            mutate(lambda n: n.__setitem__("args", []), "no args on node %d" % i)
        if n["type"] in ("displacement", "conic", "scale", "bounded", "rfunction", "soft_sum",
                         "ricci", "soft_hyper", "soft_conic", "perlin"):
            mutate(lambda n: n.__setitem__("type", {"zero": "soft_sum", "soft": "rfunction"}[doc["convention"]]),
                   "%s-convention operator on node %d" % (other, i))
        if doc["convention"] == "zero" and "args" not in n:
            mutate(lambda n: n.__setitem__("kernel", "wyvill"), "kernel in a zero scene on node %d" % i)
    d = copy.deepcopy(doc)
    d["version"] = 2
    cases.append(("version 2", d))
    d = copy.deepcopy(doc)
    d["bounds"] = {"min": [0, 0, 0]}
    cases.append(("bounds without max", d))
    for what, d in cases[:: max(1, len(cases) // 40)]:  # at most ~40 per scene, each validated by both
        mutations += 1

        def broken(l_ok, msg, s_ok=schema_accepts(d), name=os.path.basename(path), what=what):
            if s_ok or l_ok:
                failures.append("%s, %s: schema %s, library %s (%s)" % (
                    name, what, "accepts" if s_ok else "rejects", "accepts" if l_ok else "rejects", msg))
        library_then(d, broken)

# arity: the wide families take 257 and 65535 arguments (per-argument
# parameter arrays too), nobody 65536; the others stop at 256
def wide_scene(conv, kind, k, per_arg):
    sph = {"type": "sphere", "radius": 1}
    node = {"type": kind, "args": [sph] * k}
    if kind in ("displacement", "scale"):
        node.update({"op": "union", "r": [0.1] * k if per_arg else 0.1})
        if kind == "displacement":
            node["p"] = [2] * k if per_arg else 2
    if kind == "perlin":
        node["op"] = "union"
    if kind == "ricci":
        node["n"] = 2
    return {"format": "libblend-scene", "version": 1, "convention": conv, "root": node}


arity = 0
for conv, kind, k, want in (("zero", "displacement", 257, True), ("zero", "displacement", 65535, True),
                            ("zero", "displacement", 65536, False), ("zero", "min", 4096, True),
                            ("zero", "max", 65536, False), ("soft", "soft_sum", 4096, True),
                            ("soft", "ricci", 300, True), ("soft", "max", 300, True),
                            ("zero", "scale", 257, False), ("soft", "perlin", 257, False)):
    for per_arg in ((False, True) if kind == "displacement" and k < 65536 else (False,)):
        d = wide_scene(conv, kind, k, per_arg)
        arity += 1

        def wide(l_ok, msg, s_ok=schema_accepts(d), case=(conv, kind, k, want, per_arg)):
            conv, kind, k, want, per_arg = case
            if s_ok != want or l_ok != want:
                failures.append("%s %s with %d arguments%s: schema %s, library %s (%s); want %s" % (
                    conv, kind, k, " (per-argument r, p)" if per_arg else "",
                    "accepts" if s_ok else "rejects", "accepts" if l_ok else "rejects", msg,
                    "accepted" if want else "refused"))
        library_then(d, wide)

# the complete scenes in docs/scene-format.md are valid for both
doc_scenes = 0
for block in re.findall(r"```json\n(.*?)```", open(os.path.join(src, "docs", "scene-format.md")).read(), re.S):
    try:
        d = json.loads(block)
    except ValueError:
        continue  # a fragment
    if not isinstance(d, dict) or "format" not in d:
        continue  # a node, not a scene
    doc_scenes += 1

    def example(ok, msg, s_ok=schema_accepts(d)):
        if not ok or not s_ok:
            failures.append("docs/scene-format.md example: library %s, schema %s" % (msg or "accepts", s_ok))
    library_then(d, example)
if doc_scenes == 0:
    failures.append("docs/scene-format.md has no complete example scene")

# the kinds: the schema's node kinds against the library's list
doc = {"format": "libblend-scene", "version": 1, "convention": "zero", "root": {"type": "nosuchkind"}}
library_kinds = set()


def kinds(ok, msg):
    m = re.search(r"allowed: ([a-z_, ]*)", msg)
    library_kinds.update(re.findall(r"[a-z_]+", m.group(1)) if m else [])
library_then(doc, kinds)
run_library()
schema_kinds = {k.split("_", 1)[1] for k in schema["$defs"] if k.startswith(("zero_", "soft_")) and k not in ("zero_node", "soft_node")}
if not library_kinds or library_kinds != schema_kinds:
    failures.append("node kinds differ: library %s, schema %s" % (sorted(library_kinds), sorted(schema_kinds)))

for f in failures:
    print("FAIL:", f)
print("%d scenes, %d mutations, %d arity cases, %d node kinds, %d failures" % (
    len(scenes), mutations, arity, len(schema_kinds), len(failures)))
sys.exit(1 if failures else 0)
