"""Blender objects <-> libblend scene JSON (docs/scene-format.md).

to_scene(output) walks the output's child hierarchy and returns the scene as
a dict plus a map from JSON paths ($.root.args[1]) to object names, so a
library error about `$.root.args[1].r` can name the object. from_scene()
builds the hierarchy back. Numbers go through float32 (Blender stores
float32) and are written in their shortest round-trip form, so export ->
import -> export gives the same file.
"""
import json
import math

import bpy
from mathutils import Euler, Matrix, Vector

try:
    import numpy as np
except ImportError:  # Blender ships numpy; keep the module importable anyway
    np = None

#: keys each operator writes besides "type" and "args"
BLEND_KEYS = {
    "displacement": ("op", "r", "p", "m", "bulge"),
    "conic": ("op", "r", "conic_p", "m", "bulge"),
    "scale": ("op", "r", "p", "bulge_range"),
    "bounded": ("op", "p", "bounds"),
    "rfunction": ("op2",),
    "min": (), "max": (), "complement": (),
    "soft_hyper": ("op", "r", "p", "m"),
    "soft_conic": ("op", "r", "conic_p", "m"),
    "soft_sum": (), "ricci": ("n",), "perlin": ("op",),
    "local_union": ("local", "zero_scale"), "clean_union": ("zero_scale",),
    "level": ("level",),
}
#: local_union keys the panel does not show, kept as JSON text
LOCAL_EXTRA = ("feature_size", "limits", "alpha")
#: scene keys of each primitive -> settings attribute
PRIM_KEYS = {
    "sphere": (("center", "center"), ("radius", "radius")),
    "ellipsoid": (("center", "center"), ("semi_axes", "semi_axes")),
    "lp": (("center", "center"), ("semi_axes", "semi_axes"), ("exponent", "exponent")),
    "superquadric": (("center", "center"), ("semi_axes", "semi_axes"), ("e1", "e1"), ("e2", "e2")),
    "slab": (("point", "center"), ("normal", "axis"), ("half_width", "half_width")),
    "halfspace": (("point", "center"), ("normal", "axis"), ("width", "width")),
    "cylinder": (("point", "center"), ("axis", "axis"), ("radius", "radius")),
    "capsule": (("start", "start"), ("end", "end"), ("radius", "radius")),
    "torus": (("center", "center"), ("axis", "axis"), ("major_radius", "major_radius"),
              ("minor_radius", "minor_radius")),
}
EMPTY_DISPLAY = {"sphere": "SPHERE", "ellipsoid": "SPHERE", "lp": "CUBE", "superquadric": "CUBE",
                 "slab": "CUBE", "halfspace": "SINGLE_ARROW", "cylinder": "SINGLE_ARROW",
                 "capsule": "SINGLE_ARROW", "torus": "CIRCLE"}


class TreeError(Exception):
    """The object hierarchy is not a valid blend tree; the text names the object and the fix."""


def f32(v):
    """v as Blender stores it, in the shortest decimal form that reads back the same."""
    if np is None:
        return float("%.9g" % v)
    return float(repr(np.float32(v)).replace("np.float32(", "").rstrip(")"))


def vec(v):
    return [f32(c) for c in v]


def settings(obj):
    return obj.libblend


def is_node(obj):
    return obj is not None and obj.libblend.kind in ("PRIMITIVE", "BLEND")


#: during a walk of the tree (to_scene): each object's children, found in one
#: pass over the objects. Blender 3.4's Object.children scans every object of
#: the file on each call, so a walk asking each node for its children cost
#: O(n^2): 44 ms of a 512-sphere field's 80 ms scene text.
_kids = None


def _children_of(obj):
    if _kids is None:
        return obj.children
    return _kids.get(obj.as_pointer(), ())


def children(obj, role="ARG", depsgraph=None):
    """The node children of obj with the given role, in argument order; with a
    depsgraph, their evaluated copies (the values at that depsgraph's frame:
    keyframes, drivers, constraints)."""
    kids = sorted((c for c in _children_of(obj.original) if is_node(c) and
                   c.libblend.role == role), key=lambda c: (c.libblend.order, c.name))
    return [c.evaluated_get(depsgraph) for c in kids] if depsgraph is not None else kids


#: operators whose result no later blend's values can see through: a sharp
#: min / max (or a complement) of values keeps each argument's zero set
#: whatever the scale of its values, so m below them changes nothing
# blends whose surface depends only on where their arguments are inside, not
# on their values (the registry's "uses_argument_values": false; the C
# library's lb_scene_unused_m asks the same question; tests/schema/
# test_registry.py holds this list to the registry)
VALUE_BLIND = ("min", "max", "complement", "rfunction", "clean_union")


def m_has_effect(blend):
    """Whether the subsequent-blend parameter m of `blend`'s arguments can
    change the surface: m scales the blend's values outside its blending
    region and its zero set never moves (docs/operators.md, section 4), so it acts only
    through a later blend that uses those values, an ancestor that is not a
    sharp min / max / complement."""
    o = blend.parent
    while o is not None and is_node(o):
        if o.libblend.kind == "BLEND" and o.libblend.blend_type not in VALUE_BLIND:
            return True
        o = o.parent
    return False


def m_note(obj, as_argument=False):
    """The panel's warning when obj sets an m that has no effect, else "":
    a blend's own m, or (as_argument) obj's own m override as an argument."""
    s = obj.libblend
    if not as_argument:
        if s.kind == "BLEND" and "m" in BLEND_KEYS.get(s.blend_type, ()) and s.m != 1.0 \
                and not m_has_effect(obj):
            return ("m = %g has no effect: no later blend uses the values of '%s' (it is not "
                    "inside another blend). Fix: blend it with something, or leave m at 1"
                    % (s.m, obj.name))
        return ""
    p = obj.parent
    if s.arg_override and s.arg_m != 1.0 and p is not None and p.libblend.kind == "BLEND" \
            and "m" in BLEND_KEYS.get(p.libblend.blend_type, ()) and not m_has_effect(p):
        return ("own m = %g has no effect: no later blend uses the values of '%s' (it is not "
                "inside another blend). Fix: blend it with something, or leave m at 1"
                % (s.arg_m, p.name))
    return ""


def output_of(obj):
    """The OUTPUT object obj belongs to (obj itself for an output), or None."""
    while obj is not None:
        if obj.libblend.kind == "OUTPUT":
            return obj
        if not is_node(obj):
            return None
        obj = obj.parent
    return None


def _transform(obj, out, can_mirror):
    """The node's transform relative to its parent, as scene keys."""
    ident = obj.matrix_parent_inverse == Matrix.Identity(4)
    if ident and obj.rotation_mode == "XYZ":
        loc, rot, scl = Vector(obj.location), Euler(obj.rotation_euler), Vector(obj.scale)
    else:
        M = obj.matrix_parent_inverse @ obj.matrix_basis
        loc, q, scl = M.decompose()
        rot = q.to_euler("XYZ")
        R = (Matrix.Translation(loc) @ rot.to_matrix().to_4x4() @ Matrix.Diagonal(scl.to_4d()))
        err = max(abs(R[i][j] - M[i][j]) for i in range(4) for j in range(4))
        if err > 1e-5 * max(1.0, max(abs(c) for c in scl)):
            raise TreeError("object '%s': its transform relative to its parent is sheared "
                            "(a non-uniform scale above a rotation), which a scene cannot hold. "
                            "Fix: apply the parent's scale (Ctrl+A) or clear the parent inverse "
                            "(Alt+P)" % obj.name)
    if any(s < 0 for s in scl):
        if not can_mirror:
            raise TreeError("object '%s': negative scale (a mirror) on a blend node; allowed: "
                            "positive scale. Fix: mirror the primitives inside instead" % obj.name)
        scl = Vector([abs(s) for s in scl])  # primitives are symmetric about their own axes
    if any(s < 1e-6 or s > 1e6 for s in scl):
        raise TreeError("object '%s': scale %s; allowed: each in [1e-6, 1e6] (no zero scale)"
                        % (obj.name, tuple(round(s, 9) for s in scl)))
    if any(v != 0 for v in loc):
        out["translate"] = vec(loc)
    deg = [_degrees(a) for a in rot]
    if any(v != 0 for v in deg):
        out["rotate"] = deg
    if any(s != 1 for s in scl):
        s = vec(scl)
        out["scale"] = s[0] if s[0] == s[1] == s[2] else s


def _degrees(a):
    """The shortest decimal number of degrees that Blender stores as the angle a (radians)."""
    d = math.degrees(a)
    for digits in range(1, 17):
        c = float("%.*g" % (digits, d))
        if f32(math.radians(c)) == f32(a):
            return c
    return d


def _per_arg(blend, args, key):
    own = {"r": "arg_r", "p": "arg_p", "m": "arg_m"}[key]
    vals = [f32(getattr(a.libblend, own) if a.libblend.arg_override else getattr(blend.libblend, key))
            for a in args]
    return vals[0] if all(v == vals[0] for v in vals) else vals


def _material(obj, out):
    """The node's own material into its scene dict."""
    s = obj.libblend
    if not s.has_material:
        return
    try:
        mat = json.loads(s.material_extra) if s.material_extra else {}
    except ValueError:
        raise TreeError("object '%s': its kept finish is not JSON; clear it" % obj.name) from None
    mat = {k: v for k, v in mat.items() if k in ("ambient", "diffuse")}
    mat["color"] = vec(s.material_color)
    mat["specular"] = f32(s.material_specular)
    out["material"] = mat


def _node(obj, path, paths, convention, depth, dg=None):
    if depth > 64:
        raise TreeError("object '%s': the tree is nested deeper than 64 levels; allowed: 64 "
                        "(docs/scene-format.md, Limits)" % obj.name)
    paths[path] = obj.name
    s = obj.libblend
    if s.kind == "PRIMITIVE":
        out = {"type": s.prim_type}
        for key, attr in PRIM_KEYS[s.prim_type]:
            v = getattr(s, attr)
            out[key] = vec(v) if hasattr(v, "__len__") else f32(v)
        if convention == "soft":
            out["kernel"] = s.kernel
        _transform(obj, out, True)
        _material(obj, out)
        if children(obj, "ARG", dg):
            raise TreeError("object '%s': a primitive cannot have arguments (child '%s'). Fix: "
                            "parent '%s' to a blend node instead"
                            % (obj.name, children(obj)[0].name, children(obj)[0].name))
        return out
    t = s.blend_type
    if t not in BLEND_KEYS:
        raise TreeError("object '%s': unknown operator %r" % (obj.name, t))
    args = children(obj, "ARG", dg)
    if not args:
        raise TreeError("object '%s': the %s blend has no arguments. Fix: parent primitives or "
                        "blends to it (or delete it)" % (obj.name, t))
    out = {"type": t}
    keys = BLEND_KEYS[t]
    if "op" in keys:
        out["op"] = s.op
    if "op2" in keys:
        if s.op == "difference":
            raise TreeError("object '%s': an R-function blend is a union or an intersection; "
                            "allowed: union, intersection" % obj.name)
        out["op"] = s.op
    for key in ("r", "p", "m"):
        if key in keys:
            out[key] = _per_arg(obj, args, key)
    if "conic_p" in keys:
        out["p"] = f32(s.conic_p)
    if "n" in keys:
        out["n"] = f32(s.ricci_n)
    if "level" in keys:
        out["level"] = f32(s.level)
    if "bulge" in keys and s.bulge:
        out["bulge"] = {"range": s.bulge_range, "slope": s.bulge_slope, "omega": f32(s.bulge_omega)}
    if "bulge_range" in keys and s.bulge:
        out["bulge"] = {"range": True, "omega": f32(s.bulge_omega)}
    if "local" in keys:
        out["support"] = s.local_support
        out["support_factor"] = f32(s.local_support_factor)
        out["exponent"] = f32(s.local_exponent)
        if s.local_radius > 0:
            out["radius"] = f32(s.local_radius)
    if "zero_scale" in keys:
        if convention == "zero":
            out["zero_scale"] = f32(s.zero_scale)
        if s.local_extra:
            try:
                extra = json.loads(s.local_extra)
            except ValueError:
                raise TreeError("object '%s': its kept keys (More Keys) are not JSON; clear them"
                                % obj.name) from None
            out.update({k: v for k, v in extra.items() if k in LOCAL_EXTRA})
    _transform(obj, out, False)
    _material(obj, out)
    out["args"] = [_node(a, "%s.args[%d]" % (path, i), paths, convention, depth + 1, dg)
                   for i, a in enumerate(args)]
    if "bounds" in keys:
        bounds = []
        for i, a in enumerate(args):
            b = children(a, "BOUND", dg)
            if len(b) != 1:
                raise TreeError("object '%s': argument '%s' of the bounded blend needs exactly one "
                                "bounding solid, found %d. Fix: select it and use Add Bounding "
                                "Solid" % (obj.name, a.name, len(b)))
            bounds.append(_node(b[0], "%s.bounds[%d]" % (path, i), paths, convention, depth + 1,
                                dg))
        out["bounds"] = bounds
    return out


def to_scene(output, depsgraph=None, render=True):
    """(scene dict, {json path: object name}) for an OUTPUT object; with a
    depsgraph, every value as that depsgraph evaluated it (its frame)."""
    global _kids
    if _kids is not None:  # a walk inside a walk: the outer one's index holds
        return _to_scene(output, depsgraph, render)
    _kids = {}
    for o in bpy.data.objects:
        if o.parent is not None:
            _kids.setdefault(o.parent.as_pointer(), []).append(o)
    try:
        return _to_scene(output, depsgraph, render)
    finally:
        _kids = None


def _to_scene(output, depsgraph, render):
    if depsgraph is not None:
        output = output.evaluated_get(depsgraph)
    s = output.libblend
    roots = children(output, "ARG", depsgraph)
    if len(roots) != 1:
        raise TreeError("field '%s' has %d root nodes; allowed: exactly one. Fix: %s"
                        % (output.name, len(roots),
                           "add a primitive or a blend to it" if not roots else
                           "select them and use Blend Selected to combine them"))
    lo, hi = vec(s.bounds_min), vec(s.bounds_max)
    for i in range(3):
        if not lo[i] < hi[i]:
            raise TreeError("field '%s': region min %s is not below max %s on axis %s; allowed: "
                            "min < max on every axis" % (output.name, lo, hi, "xyz"[i]))
    paths = {}
    scene = {"format": "libblend-scene", "version": 1}
    if s.title:
        scene["title"] = s.title
    if s.description:
        scene["description"] = s.description
    scene["convention"] = s.convention
    scene["bounds"] = {"min": lo, "max": hi}
    scene["root"] = _node(roots[0], "$.root", paths, s.convention, 0, depsgraph)
    if render:
        from . import render_section
        section = render_section.to_section(output.original)
        if section:
            scene["render"] = section
    return scene, paths


def to_json(output, depsgraph=None, render=True, compact=False):
    """The scene as JSON text; render=False leaves the render section out
    (meshing: a moved camera changes no mesh). compact=True writes it
    without indentation (json's C encoder: 64 spheres in 1 ms, not 3), for
    text that only the library reads."""
    scene, paths = to_scene(output, depsgraph, render)
    return (json.dumps(scene, separators=(",", ":")) if compact else json.dumps(scene, indent=2)), paths


def explain(message, paths):
    """Prefix a library message with the object its JSON path points to."""
    import re
    m = re.search(r"\$\.root[\w\[\].]*", message)
    if not m:
        return message
    p = m.group(0)
    best = max((k for k in paths if p == k or p.startswith(k + ".") or p.startswith(k + "[")),
               key=len, default=None)
    return "object '%s': %s" % (paths[best], message) if best else message


# ---------------------------------------------------------------------------- import

def _basis(node):
    S = node.get("scale", 1)
    S = [S, S, S] if isinstance(S, (int, float)) else S
    R = Euler([math.radians(a) for a in node.get("rotate", [0, 0, 0])], "XYZ")
    T = node.get("translate", [0, 0, 0])
    return Matrix.Translation(T) @ R.to_matrix().to_4x4() @ Matrix.Diagonal(list(S) + [1])


def _new_empty(name, parent, collection, display):
    obj = bpy.data.objects.new(name, None)
    obj.empty_display_type = display
    obj.empty_display_size = 0.5
    collection.objects.link(obj)
    obj.parent = parent
    obj.matrix_parent_inverse = Matrix.Identity(4)
    return obj


def _set_basis(obj, M):
    """Set obj's location / rotation / scale from M; False when M is sheared."""
    loc, q, scl = M.decompose()
    rot = q.to_euler("XYZ")
    R = Matrix.Translation(loc) @ rot.to_matrix().to_4x4() @ Matrix.Diagonal(scl.to_4d())
    if max(abs(R[i][j] - M[i][j]) for i in range(4) for j in range(4)) > 1e-5 * max(1.0, *scl):
        return False
    obj.rotation_mode = "XYZ"
    obj.location, obj.rotation_euler, obj.scale = loc, rot, scl
    return True


def _set_node_transform(obj, node):
    """The node's own transform, value for value (exact in float32)."""
    S = node.get("scale", 1)
    obj.rotation_mode = "XYZ"
    obj.scale = [S, S, S] if isinstance(S, (int, float)) else S
    obj.rotation_euler = [math.radians(a) for a in node.get("rotate", [0, 0, 0])]
    obj.location = node.get("translate", [0, 0, 0])


def from_scene(scene, collection, name="libblend field"):
    """Build an OUTPUT object (and its node objects) from a scene dict that
    libblend has already validated. Refs are expanded (Blender objects form a
    tree). Returns the output object."""
    defs = scene.get("defs", {})
    me = bpy.data.meshes.new(name)
    out = bpy.data.objects.new(name, me)
    collection.objects.link(out)
    s = out.libblend
    s.kind = "OUTPUT"
    s.live = False  # no remesh while the tree is half built
    s.convention = scene["convention"]
    if "bounds" in scene:
        s.bounds_min, s.bounds_max = scene["bounds"]["min"], scene["bounds"]["max"]
    s.fit_region = False  # the file's bounds are its author's region (as blendtool meshes it)
    s.title = scene.get("title", "")
    s.description = scene.get("description", "")
    s.render_json = json.dumps(scene["render"]) if "render" in scene else ""

    TKEYS = ("translate", "rotate", "scale")

    def build(node, parent, role, order, outer=None):
        """outer: the transform of the refs that led here (a ref's transform
        applies on top of its def's own)."""
        if "ref" in node:
            M = _basis(node) if outer is None else outer @ _basis(node)
            target = defs[node["ref"]]
            if "material" in node and "material" not in target:
                # a ref's material is its def's unless the def names one (libblend's rule)
                target = dict(target, material=node["material"])
            if outer is None and "ref" not in target and not any(k in target for k in TKEYS):
                # the common case: the ref's transform is the node's, exactly
                target = dict(target, **{k: node[k] for k in TKEYS if k in node})
                M = None
            return build(target, parent, role, order, M)
        if "args" in node:
            obj = _new_empty(node["type"], parent, collection, "PLAIN_AXES")
        else:
            obj = _new_empty(node["type"], parent, collection, EMPTY_DISPLAY[node["type"]])
        if outer is None:
            _set_node_transform(obj, node)
        elif not _set_basis(obj, outer @ _basis(node)):
            # a ref's transform over its def's does not reduce to one T R S: keep the def's on
            # the node and wrap it in a one-argument sharp blend carrying the ref's
            wrap = obj
            wrap.name = "ref"
            ws = wrap.libblend
            ws.kind, ws.blend_type, ws.role, ws.order = "BLEND", \
                ("min" if scene["convention"] == "zero" else "max"), role, order
            _set_basis(wrap, outer)  # a ref's own transform is a plain T R S
            return build(node, wrap, "ARG", 0)
        st = obj.libblend
        st.role, st.order = role, order
        if "material" in node:
            m = node["material"]
            st.has_material = True
            st.material_color = m.get("color", (0.8, 0.8, 0.8))
            st.material_specular = m.get("specular", 0.3)
            kept = {k: m[k] for k in ("ambient", "diffuse") if k in m}
            st.material_extra = json.dumps(kept) if kept else ""
        if "args" not in node:
            st.kind = "PRIMITIVE"
            st.prim_type = node["type"]
            for key, attr in PRIM_KEYS[node["type"]]:
                if key in node:
                    setattr(st, attr, node[key])
            if "kernel" in node:
                st.kernel = node["kernel"]
            return obj
        st.kind = "BLEND"
        t = node["type"]
        st.blend_type = t
        if "op" in node:
            st.op = node["op"]
        k = len(node["args"])
        per = {}
        for key in ("r", "p", "m"):
            if key in node and key in BLEND_KEYS[t]:
                v = node[key]
                per[key] = v if isinstance(v, list) else [v] * k
                setattr(st, key, per[key][0])
        if t in ("conic", "soft_conic") and "p" in node:
            st.conic_p = node["p"]
        if "n" in node:
            st.ricci_n = node["n"]
        if "level" in node:
            st.level = node["level"]
        if t == "local_union":
            st.local_support = node.get("support", "progressive")
            st.local_support_factor = node.get("support_factor", 0.25)
            st.local_exponent = node.get("exponent", 2.0)
            st.local_radius = node.get("radius", 0.0)
        if t in ("local_union", "clean_union"):
            st.zero_scale = node.get("zero_scale", 1.0)
            extra = {k: node[k] for k in LOCAL_EXTRA if k in node}
            st.local_extra = json.dumps(extra) if extra else ""
        if "bulge" in node:
            b = node["bulge"]
            st.bulge = True
            st.bulge_range = b.get("range", True)
            st.bulge_slope = b.get("slope", False)
            st.bulge_omega = b.get("omega", 0.001)
        for i, a in enumerate(node["args"]):
            child = build(a, obj, "ARG", i)
            cs = child.libblend
            if any(per[key][i] != per[key][0] for key in per):
                cs.arg_override = True
                for key in per:
                    setattr(cs, "arg_" + key, per[key][i])
                for key in ("r", "p", "m"):
                    if key not in per:
                        setattr(cs, "arg_" + key, getattr(st, key))
            if "bounds" in node:
                build(node["bounds"][i], child, "BOUND", 0)
        return obj

    build(scene["root"], out, "ARG", 0)
    s.live = True
    return out
