"""Operators (F3 search: "libblend"). Each one is undoable and reports
problems in Blender's status bar instead of raising."""
import json
import os
import shutil

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatVectorProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper
from mathutils import Matrix

from . import atomic, bake, binding, compat, libhandle, live, props, render_section, tree


def _active(context):
    return context.view_layer.objects.active


def _selected(context):
    return [o for o in compat.view_layer_objects(context.view_layer) if o.select_get()]


def _make_active(context, obj):
    for o in _selected(context):
        o.select_set(False)
    obj.select_set(True)
    context.view_layer.objects.active = obj


def _next_order(parent):
    args = tree.children(parent)
    return (max(a.libblend.order for a in args) + 1) if args else 0


def _target_parent(context, op):
    """Where a new node goes: the active blend or output, or the active node's parent."""
    a = _active(context)
    if a is None or tree.output_of(a) is None:
        op.report({"ERROR"}, "select a libblend field (Add > libblend Field) or one of its nodes "
                             "first")
        return None
    if a.libblend.kind in ("OUTPUT", "BLEND"):
        return a
    return a.parent


def _root_taken(op, parent, fix):
    """A field holds one root node: report (with the fix) when parent is a
    field that already has it."""
    if parent.libblend.kind == "OUTPUT" and tree.children(parent):
        op.report({"ERROR"}, "field '%s' already has its root node; %s" % (parent.name, fix))
        return True
    return False


def _new_node(context, parent, name, display):
    obj = bpy.data.objects.new(name, None)
    obj.empty_display_type = display
    obj.empty_display_size = 0.5
    coll = parent.users_collection[0] if parent.users_collection else context.collection
    coll.objects.link(obj)
    obj.parent = parent
    obj.matrix_parent_inverse = Matrix.Identity(4)
    return obj


def _blend_items(self, context):
    a = context.view_layer.objects.active if context else None
    out = tree.output_of(a) if a else None
    if out is not None and out.libblend.convention == "soft":
        return props.BLENDS_SOFT + props.BLENDS_SHARP + props.BLENDS_BOTH
    return props.BLENDS_ZERO + props.BLENDS_SHARP + props.BLENDS_BOTH


class LIBBLEND_OT_add_field(bpy.types.Operator):
    """Add a libblend field: a mesh object meshed from a blend tree of primitives"""
    bl_idname = "libblend.add_field"
    bl_label = "libblend Field"
    bl_options = {"REGISTER", "UNDO"}

    convention: EnumProperty(name="Convention", items=[
        ("zero", "Zero (distance-like)", ""), ("soft", "Soft (kernels)", "")])
    with_sphere: BoolProperty(name="Start with a Sphere", default=True)

    def execute(self, context):
        me = bpy.data.meshes.new("libblend field")
        out = bpy.data.objects.new("libblend field", me)
        context.collection.objects.link(out)
        out.location = context.scene.cursor.location
        s = out.libblend
        s.kind = "OUTPUT"
        s.live = False
        s.convention = self.convention
        s.fit_region = True  # a new field's region follows it (imported scenes keep theirs)
        if self.with_sphere:
            sph = _new_node(context, out, "sphere", "SPHERE")
            sph.libblend.kind = "PRIMITIVE"
            sph.libblend.prim_type = "sphere"
        s.live = True
        _make_active(context, out)
        if self.with_sphere:
            live.update_now(out)
        return {"FINISHED"}


class LIBBLEND_OT_add_primitive(bpy.types.Operator):
    """Add a libblend primitive under the active blend (or field)"""
    bl_idname = "libblend.add_primitive"
    bl_label = "Add libblend Primitive"
    bl_options = {"REGISTER", "UNDO"}

    prim_type: EnumProperty(name="Primitive", items=props.PRIMITIVES)
    location: FloatVectorProperty(name="Location", subtype="TRANSLATION",
                                  description="relative to the parent node")
    rotation: FloatVectorProperty(name="Rotation", subtype="EULER")

    def execute(self, context):
        parent = _target_parent(context, self)
        if parent is None:
            return {"CANCELLED"}
        if _root_taken(self, parent, "select a blend node to add the primitive to"):
            return {"CANCELLED"}
        obj = _new_node(context, parent, self.prim_type, tree.EMPTY_DISPLAY[self.prim_type])
        obj.location, obj.rotation_euler = self.location, self.rotation
        s = obj.libblend
        s.kind, s.prim_type, s.order = "PRIMITIVE", self.prim_type, _next_order(parent)
        _make_active(context, obj)
        live.mark_dirty(obj)
        return {"FINISHED"}


class _BlendOperator:
    blend_type: EnumProperty(name="Operator", items=_blend_items)
    op: EnumProperty(name="Set Operation", items=props.OPS)

    def execute(self, context):
        a = _active(context)
        if a is None or tree.output_of(a) is None:
            self.report({"ERROR"}, "select a libblend field or one of its nodes first")
            return {"CANCELLED"}
        if self.wrap_selected:
            sel = [o for o in _selected(context) if tree.is_node(o)]
            if not sel:
                self.report({"ERROR"}, "select the nodes to blend (primitives or blends of one "
                                       "field)")
                return {"CANCELLED"}
            return self._wrap(context, sel)
        parent = a if a.libblend.kind in ("OUTPUT", "BLEND") else a.parent
        if _root_taken(self, parent, "select it and use Blend Selected to blend it with new "
                                     "nodes"):
            return {"CANCELLED"}
        obj = self._new(context, parent, _next_order(parent), "ARG")
        _make_active(context, obj)
        live.mark_dirty(obj)
        return {"FINISHED"}

    def _new(self, context, parent, order, role):
        obj = _new_node(context, parent, self.blend_type, "PLAIN_AXES")
        s = obj.libblend
        s.kind, s.blend_type, s.op, s.order, s.role = "BLEND", self.blend_type, self.op, order, role
        return obj

    def _wrap(self, context, sel):
        """The new blend takes the selected nodes' place (parent, position,
        role, and a lone node's own r / p / m there); they become its
        arguments, in their order, where they are in the world."""
        parent = sel[0].parent
        if any(o.parent != parent for o in sel):
            self.report({"ERROR"}, "the selected nodes have different parents; select siblings "
                                   "to blend them")
            return {"CANCELLED"}
        if len({o.libblend.role for o in sel}) > 1:
            self.report({"ERROR"}, "the selection mixes arguments and a bounding solid; select "
                                   "arguments only, or the bounding solid alone")
            return {"CANCELLED"}
        sel = sorted(sel, key=lambda o: (o.libblend.order, o.name))
        obj = self._new(context, parent, sel[0].libblend.order, sel[0].libblend.role)
        if len(sel) == 1:  # the blend stands where the node stood, as the same argument
            src, dst = sel[0].libblend, obj.libblend
            dst.arg_override, dst.arg_r, dst.arg_p, dst.arg_m = \
                src.arg_override, src.arg_r, src.arg_p, src.arg_m
            src.arg_override = False
        for i, o in enumerate(sel):
            w = o.matrix_world.copy()
            o.parent = obj
            o.matrix_parent_inverse = Matrix.Identity(4)
            o.matrix_world = w
            o.libblend.order, o.libblend.role = i, "ARG"
        _make_active(context, obj)
        live.mark_dirty(obj)
        return {"FINISHED"}


class LIBBLEND_OT_add_blend(_BlendOperator, bpy.types.Operator):
    """Add a libblend blend node under the active blend (or field); with Blend Selected, the
    selected nodes become its arguments instead"""
    bl_idname = "libblend.add_blend"
    bl_label = "Add libblend Blend"
    bl_options = {"REGISTER", "UNDO"}

    wrap_selected: BoolProperty(name="Blend Selected", default=False,
                                description="wrap the selected nodes in the new blend, at their "
                                "place in the tree")


class LIBBLEND_OT_blend_selected(_BlendOperator, bpy.types.Operator):
    """Wrap the selected nodes in a new blend at their place in the tree"""
    bl_idname = "libblend.blend_selected"
    bl_label = "Blend Selected"
    bl_options = {"REGISTER", "UNDO"}

    wrap_selected: BoolProperty(name="Blend Selected", default=True, options={"HIDDEN"})


class LIBBLEND_OT_add_bound(bpy.types.Operator):
    """Add a bounding solid to the active node (for bounded blends): a larger copy of it"""
    bl_idname = "libblend.add_bound"
    bl_label = "Add Bounding Solid"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        a = context.view_layer.objects.active
        return a is not None and a.libblend.kind == "PRIMITIVE"

    def execute(self, context):
        a = _active(context)
        if tree.children(a, "BOUND"):
            self.report({"ERROR"}, "'%s' already has a bounding solid" % a.name)
            return {"CANCELLED"}
        b = _new_node(context, a, a.libblend.prim_type + " bound", "SPHERE")
        for key in a.libblend.bl_rna.properties.keys():
            if key not in ("rna_type", "name", "role", "order", "arg_override"):
                try:
                    setattr(b.libblend, key, getattr(a.libblend, key))
                except (AttributeError, TypeError):
                    pass
        b.libblend.role = "BOUND"
        b.scale = (1.5, 1.5, 1.5)
        b.empty_display_type = "SPHERE"
        _make_active(context, b)
        live.mark_dirty(b)
        return {"FINISHED"}


class LIBBLEND_OT_move_argument(bpy.types.Operator):
    """Move the active node one place up or down among its parent's arguments"""
    bl_idname = "libblend.move_argument"
    bl_label = "Move Argument"
    bl_options = {"REGISTER", "UNDO"}

    direction: EnumProperty(items=[("UP", "Up", ""), ("DOWN", "Down", "")])

    def execute(self, context):
        a = _active(context)
        if not tree.is_node(a) or a.parent is None:
            return {"CANCELLED"}
        args = tree.children(a.parent)
        i = args.index(a)
        j = i - 1 if self.direction == "UP" else i + 1
        if 0 <= j < len(args):
            args[i], args[j] = args[j], args[i]
        for k, o in enumerate(args):
            o.libblend.order = k
        live.mark_dirty(a)
        return {"FINISHED"}


def _refused(op, e, paths):
    """Report a tree or library error (naming the object its JSON path points
    to) and cancel."""
    op.report({"ERROR"}, tree.explain(str(e), paths) if isinstance(e, binding.LibblendError)
              else str(e))
    return {"CANCELLED"}


def _output(context, op):
    a = _active(context)
    out = tree.output_of(a) if a else None
    if out is None:
        op.report({"ERROR"}, "select a libblend field or one of its nodes first")
    return out


class LIBBLEND_OT_update_mesh(bpy.types.Operator):
    """Remesh the active libblend field now"""
    bl_idname = "libblend.update_mesh"
    bl_label = "Update libblend Mesh"
    bl_options = {"REGISTER", "UNDO"}

    final: BoolProperty(name="Render Resolution", default=False)

    def execute(self, context):
        out = _output(context, self)
        if out is None:
            return {"CANCELLED"}
        ok, msg = live.update_now(out, final=self.final)
        self.report({"INFO"} if ok else {"ERROR"}, msg)
        return {"FINISHED"} if ok else {"CANCELLED"}


class LIBBLEND_OT_reload_library(bpy.types.Operator):
    """Load libblend.so again (after installing it or changing its path)"""
    bl_idname = "libblend.reload_library"
    bl_label = "Reload libblend Library"

    def execute(self, context):
        ok, msg = libhandle.reload_library()
        self.report({"INFO"} if ok else {"ERROR"}, msg)
        return {"FINISHED"} if ok else {"CANCELLED"}


def _atomic_write(path, text):
    fd, tmp = atomic.temp_beside(path, ".libblend-")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        atomic.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


class LIBBLEND_OT_import_scene(bpy.types.Operator, ImportHelper):
    """Import a libblend scene file (.json) as a field with its blend tree"""
    bl_idname = "libblend.import_scene"
    bl_label = "Import libblend Scene"
    bl_options = {"REGISTER", "UNDO"}
    filename_ext = ".json"
    filter_glob: StringProperty(default="*.json", options={"HIDDEN"})
    with_render: BoolProperty(name="Camera, Lights, Material", default=True,
                              description="create what the scene's render section describes "
                              "(and make its camera the scene's camera)")

    def execute(self, context):
        try:
            lib = libhandle.library()
            # libblend validates first: the same messages as blendtool (file:line:col, JSON path)
            lib.load_scene(self.filepath).close()
            with open(self.filepath, encoding="utf-8") as f:
                scene = json.load(f)
        except (binding.LibblendError, OSError, ValueError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        name = scene.get("title") or os.path.splitext(os.path.basename(self.filepath))[0]
        out = tree.from_scene(scene, context.collection, name)
        if self.with_render and "render" in scene:
            render_section.create(out, scene["render"], context.collection, context.scene)
        _make_active(context, out)
        ok, msg = live.update_now(out)
        self.report({"INFO"} if ok else {"WARNING"}, msg)
        return {"FINISHED"}


class LIBBLEND_OT_export_scene(bpy.types.Operator, ExportHelper):
    """Export the active libblend field as a scene file (.json) for blendtool and batch jobs"""
    bl_idname = "libblend.export_scene"
    bl_label = "Export libblend Scene"
    filename_ext = ".json"
    filter_glob: StringProperty(default="*.json", options={"HIDDEN"})

    def execute(self, context):
        out = _output(context, self)
        if out is None:
            return {"CANCELLED"}
        try:
            text, paths, _lo, _hi, _cell = live.scene_text(out)
            libhandle.library().parse_scene(text, os.path.basename(self.filepath)).close()
            _atomic_write(self.filepath, text + "\n")
        except (tree.TreeError, binding.LibblendError) as e:
            return _refused(self, e, paths)
        except OSError as e:
            self.report({"ERROR"}, "cannot write %s: %s" % (self.filepath, e.strerror))
            return {"CANCELLED"}
        self.report({"INFO"}, "wrote %s" % self.filepath)
        return {"FINISHED"}


class LIBBLEND_OT_bake(bpy.types.Operator):
    """Mesh the active field at render resolution for every frame of a range into its bake
    folder (one file per frame), and use the bake for renders and frame changes"""
    bl_idname = "libblend.bake"
    bl_label = "Bake libblend Field"

    frame_start: IntProperty(name="Start", default=-1, description="first frame (-1: the "
                             "scene's start)")
    frame_end: IntProperty(name="End", default=-1, description="last frame (-1: the scene's end)")
    frame_step: IntProperty(name="Step", default=1, min=1)

    def execute(self, context):
        out = _output(context, self)
        if out is None:
            return {"CANCELLED"}
        sc = context.scene
        a = sc.frame_start if self.frame_start < 0 else self.frame_start
        b = sc.frame_end if self.frame_end < 0 else self.frame_end
        if b < a:
            self.report({"ERROR"}, "frame range %d - %d is empty; allowed: start <= end" % (a, b))
            return {"CANCELLED"}
        try:
            n, seconds = live.bake_frames(out, sc, range(a, b + 1, self.frame_step),
                                          context.window_manager)
        except (bake.CacheError, tree.TreeError, binding.LibblendError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        except OSError as e:
            self.report({"ERROR"}, "cannot write the bake of '%s': %s" % (out.name, e))
            return {"CANCELLED"}
        self.report({"INFO"}, out.libblend.bake_info)
        return {"FINISHED"}


class LIBBLEND_OT_bake_clear(bpy.types.Operator):
    """Delete the active field's baked frames and stop using them"""
    bl_idname = "libblend.bake_clear"
    bl_label = "Clear libblend Bake"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        out = _output(context, self)
        if out is None:
            return {"CANCELLED"}
        try:
            n = bake.clear(bake.folder(out))
        except (bake.CacheError, OSError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        out.libblend.use_bake = False
        out.libblend.bake_info = ""
        live.update_now(out)
        self.report({"INFO"}, "deleted %d baked frames of '%s'" % (n, out.name))
        return {"FINISHED"}


class LIBBLEND_OT_apply(bpy.types.Operator):
    """Convert the active field to a plain mesh object (its current state, meshed at a chosen
    resolution); the blend tree is removed unless Keep Field is on"""
    bl_idname = "libblend.apply"
    bl_label = "Apply libblend Field"
    bl_options = {"REGISTER", "UNDO"}

    resolution: IntProperty(name="Resolution", default=0, min=0, max=8192,
                            description="cells along the region's longest side (0: the field's "
                            "render resolution)")
    keep_field: BoolProperty(name="Keep Field", default=False,
                             description="keep the field and its tree next to the new mesh")

    def execute(self, context):
        out = _output(context, self)
        if out is None:
            return {"CANCELLED"}
        res = self.resolution or out.libblend.render_resolution
        paths = {}
        try:
            job = live.prepare(out, res)
            paths = job.paths
            job.run()
            if job.error:
                raise binding.LibblendError(job.error)
        except (tree.TreeError, binding.LibblendError) as e:
            return _refused(self, e, paths)
        name = out.name
        me = bpy.data.meshes.new(name)
        for m in out.data.materials:  # first: the nodes' materials reuse these slots
            me.materials.append(m)
        live.set_mesh_data(me, job.mesh, out.libblend.normals)
        obj = bpy.data.objects.new(name + " mesh", me)
        for c in out.users_collection:
            c.objects.link(obj)
        obj.matrix_world = out.matrix_world.copy()
        if not self.keep_field:
            for o in out.children_recursive:
                if tree.is_node(o):
                    bpy.data.objects.remove(o)
            old = out.data
            bpy.data.objects.remove(out)
            if old.users == 0:
                bpy.data.meshes.remove(old)
            obj.name = name
        _make_active(context, obj)
        self.report({"INFO"}, "'%s': %d triangles at %d cells" % (obj.name, len(job.mesh.triangles),
                                                                  res))
        return {"FINISHED"}


def include_file():
    """libblend.inc shipped with the add-on (or next to the source tree)."""
    here = os.path.dirname(os.path.abspath(__file__))
    for p in (os.path.join(here, "povray", "libblend.inc"),
              os.path.join(here, "..", "..", "povray_include", "libblend.inc")):
        if os.path.exists(p):
            return os.path.normpath(p)
    return None


class LIBBLEND_OT_export_pov(bpy.types.Operator, ExportHelper):
    """Export the active libblend field as a POV-Ray scene (isosurface with an exact max_gradient)"""
    bl_idname = "libblend.export_pov"
    bl_label = "Export POV-Ray Scene"
    filename_ext = ".pov"
    filter_glob: StringProperty(default="*.pov", options={"HIDDEN"})

    include_only: BoolProperty(name="Functions Only", default=False,
                               description="only the #declare'd functions (root: LB_Field)")

    def execute(self, context):
        out = _output(context, self)
        if out is None:
            return {"CANCELLED"}
        paths = {}
        try:
            text, paths, _lo, _hi, _cell = live.scene_text(out)
            lib = libhandle.library()
            with lib.parse_scene(text, out.name) as scene, scene.compile() as ev:
                g = scene.write_pov(ev, self.filepath, include_only=self.include_only,
                                    threads=libhandle.threads())
            inc = include_file()
            dst = os.path.join(os.path.dirname(os.path.abspath(self.filepath)), "libblend.inc")
            if inc and os.path.abspath(inc) != dst:  # render with: povray +I<file> (no +L needed)
                fd, tmp = atomic.temp_beside(dst, ".libblend-")
                os.close(fd)
                try:
                    shutil.copyfile(inc, tmp)
                    atomic.replace(tmp, dst)
                except BaseException:
                    if os.path.exists(tmp):
                        os.unlink(tmp)
                    raise
        except (tree.TreeError, binding.LibblendError) as e:
            return _refused(self, e, paths)
        except OSError as e:
            self.report({"ERROR"}, "cannot write next to %s: %s" % (self.filepath, e))
            return {"CANCELLED"}
        self.report({"INFO"}, "wrote %s (max_gradient %.4g)" % (self.filepath, g))
        return {"FINISHED"}


CLASSES = [LIBBLEND_OT_add_field, LIBBLEND_OT_add_primitive, LIBBLEND_OT_add_blend,
           LIBBLEND_OT_blend_selected, LIBBLEND_OT_add_bound, LIBBLEND_OT_bake,
           LIBBLEND_OT_bake_clear, LIBBLEND_OT_apply, LIBBLEND_OT_move_argument,
           LIBBLEND_OT_update_mesh, LIBBLEND_OT_reload_library, LIBBLEND_OT_import_scene, LIBBLEND_OT_export_scene,
           LIBBLEND_OT_export_pov]
