"""The sidebar panel (View3D > N > libblend), menus and add-on preferences."""
import bpy
from bpy.props import FloatProperty, IntProperty, StringProperty

from . import libhandle, live, tree


def _viewport_simplify_changed(self, context):
    """Every live field's viewport mesh follows the new value."""
    for obj in bpy.data.objects:
        if tree.is_node(obj) and obj.libblend.kind == "OUTPUT":
            live.mark_dirty(obj)


class LIBBLEND_AP_preferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    library_path: StringProperty(name="Library", subtype="FILE_PATH",
                                 description="libblend.so to load instead of the add-on's own "
                                 "copy (empty: $LIBBLEND_LIBRARY, then the add-on's lib/)")
    threads: IntProperty(name="Threads", default=0, min=0, max=256,
                         description="meshing threads (0 = one per CPU, 1 = no extra threads)")
    viewport_simplify: FloatProperty(
        name="Viewport Simplify", default=libhandle.VIEWPORT_SIMPLIFY, min=0.0, max=1.0, step=5,
        precision=2,
        update=_viewport_simplify_changed,
        description="the viewport's meshes of fields whose Simplify is 0 and Sharp Features off: "
        "cells of twice the size wherever the surface stays within this many cells of the field "
        "(Coarse First): fewer triangles and faster live updates. Renders, bakes and Apply are "
        "not simplified. 0 = off")

    def draw(self, context):
        col = self.layout.column()
        col.prop(self, "library_path")
        col.prop(self, "threads")
        col.prop(self, "viewport_simplify")
        _library_box(col)


def _library_box(layout):
    ok, msg = libhandle.library_status()
    if ok:
        layout.label(text=msg, icon="CHECKMARK")
        return True
    box = layout.box()
    box.alert = True
    box.label(text="libblend library not available", icon="ERROR")
    for line in _wrap(msg, 60):
        box.label(text=line)
    box.operator("libblend.reload_library", icon="FILE_REFRESH")
    return False


def _wrap(text, width):
    words, lines, cur = text.split(), [], ""
    for w in words:
        if len(cur) + len(w) + 1 > width and cur:
            lines.append(cur)
            cur = w
        else:
            cur = (cur + " " + w).strip()
    if cur:
        lines.append(cur)
    return lines


def _note(layout, text):
    """A warning box (an m that has no effect, ...): red, wrapped."""
    if not text:
        return
    box = layout.box()
    box.alert = True
    for i, line in enumerate(_wrap(text, 50)):
        box.label(text=line, icon="ERROR" if i == 0 else "NONE")


class LIBBLEND_PT_panel(bpy.types.Panel):
    bl_label = "libblend"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "libblend"

    def draw(self, context):
        layout = self.layout
        if not _library_box(layout):
            return
        obj = context.view_layer.objects.active
        out = tree.output_of(obj) if obj else None
        if out is None:
            layout.operator("libblend.add_field", icon="META_BALL")
            layout.operator("libblend.import_scene", icon="IMPORT")
            return
        s = obj.libblend
        if s.kind == "OUTPUT":
            self._output(layout, obj)
        elif s.kind == "PRIMITIVE":
            self._primitive(layout, obj)
        else:
            self._blend(layout, obj)
        if s.kind != "OUTPUT" and s.role == "ARG":
            row = layout.row(align=True)
            row.prop(s, "has_material")
            if s.has_material:
                row.prop(s, "material_color", text="")
                row.prop(s, "material_specular")
        if s.kind != "OUTPUT" and obj.parent is not None and obj.parent.libblend.kind == "BLEND" \
                and s.role == "ARG":
            self._as_argument(layout, obj)
        st = live.state_of(out)
        if st.status:
            box = layout.box()
            box.alert = st.error
            for line in _wrap(st.status, 50):
                box.label(text=line, icon="ERROR" if st.error else "NONE")
        _note(layout, getattr(st, "clip_warning", ""))
        row = layout.row(align=True)
        row.operator("libblend.update_mesh", icon="FILE_REFRESH").final = False
        row.operator("libblend.update_mesh", text="Render Resolution").final = True
        row = layout.row(align=True)
        row.operator("libblend.export_scene", text="Scene .json", icon="EXPORT")
        row.operator("libblend.export_pov", text="POV-Ray", icon="EXPORT")

    def _output(self, layout, obj):
        s = obj.libblend
        layout.label(text="Field: " + obj.name, icon="META_BALL")
        layout.prop(s, "convention")
        layout.prop(s, "fit_region")
        st = live.state_of(obj)
        if s.fit_region and st.region is not None:
            lo, hi = st.region
            layout.label(text="fitted: (%s) to (%s)" % (", ".join("%.3g" % v for v in lo),
                                                         ", ".join("%.3g" % v for v in hi)))
        col = layout.column(align=True)
        col.label(text="Search Around (Fit Region)" if s.fit_region else "Region")
        col.prop(s, "bounds_min")
        col.prop(s, "bounds_max")
        row = layout.row(align=True)
        row.label(text="Resolution")
        row.prop(s, "preview_resolution")
        row.prop(s, "render_resolution")
        layout.prop(s, "live")
        layout.prop(s, "normals")
        layout.prop(s, "open_boundary")
        layout.prop(s, "sharp_features")
        layout.prop(s, "merge_flat")
        layout.prop(s, "simplify")
        if s.simplify > 0.0:
            layout.prop(s, "simplify_method")
        else:
            vs = live.viewport_simplify(obj)
            if vs > 0.0:  # the preference at work: say so where Simplify is
                layout.label(text="Viewport: Coarse First %.2g cells (Preferences)" % vs,
                             icon="INFO")
        box = layout.box()
        box.label(text="Bake (render resolution, one file per frame)")
        box.prop(s, "bake_dir")
        row = box.row(align=True)
        row.operator("libblend.bake", icon="FILE_CACHE")
        row.operator("libblend.bake_clear", text="Clear", icon="TRASH")
        box.prop(s, "use_bake")
        if s.bake_info:
            for line in _wrap(s.bake_info, 50):
                box.label(text=line)
        row = layout.row(align=True)
        row.prop(s, "render_camera")
        layout.operator("libblend.apply", icon="MESH_DATA")
        self._tree(layout, obj)

    def _tree(self, layout, out):
        box = layout.box()
        box.label(text="Blend tree")

        def show(o, depth):
            row = box.row()
            row.label(text="    " * depth + o.name, icon="MESH_UVSPHERE" if
                      o.libblend.kind == "PRIMITIVE" else "NODETREE")
            for c in tree.children(o):
                show(c, depth + 1)
        for c in tree.children(out):
            show(c, 0)
        row = box.row(align=True)
        row.operator_menu_enum("libblend.add_primitive", "prim_type", text="Primitive")
        row.operator_menu_enum("libblend.add_blend", "blend_type", text="Blend")
        row.operator_menu_enum("libblend.blend_selected", "blend_type", text="Blend Selected")

    def _primitive(self, layout, obj):
        s = obj.libblend
        layout.label(text="Primitive: " + obj.name, icon="MESH_UVSPHERE")
        layout.prop(s, "prim_type")
        for key, attr in tree.PRIM_KEYS[s.prim_type]:
            layout.prop(s, attr, text=key.replace("_", " ").title())
        out = tree.output_of(obj)
        if out is not None and out.libblend.convention == "soft":
            layout.prop(s, "kernel")
        if s.role == "BOUND":
            layout.label(text="Bounding solid of " + obj.parent.name, icon="SHADING_BBOX")
        else:
            layout.operator("libblend.add_bound", icon="SHADING_BBOX")
        row = layout.row(align=True)
        row.operator_menu_enum("libblend.blend_selected", "blend_type", text="Blend Selected")

    def _blend(self, layout, obj):
        s = obj.libblend
        layout.label(text="Blend: " + obj.name, icon="NODETREE")
        layout.prop(s, "blend_type")
        keys = tree.BLEND_KEYS.get(s.blend_type, ())
        if "op" in keys or "op2" in keys:
            layout.prop(s, "op")
        for k in ("r", "p", "m"):
            if k in keys:
                layout.prop(s, k)
        _note(layout, tree.m_note(obj))
        if "conic_p" in keys:
            layout.prop(s, "conic_p")
        if "n" in keys:
            layout.prop(s, "ricci_n")
        if "level" in keys:
            layout.prop(s, "level")
        if "local" in keys:
            layout.prop(s, "local_exponent")
            layout.prop(s, "local_support")
            if s.local_support == "progressive":
                layout.prop(s, "local_support_factor")
            layout.prop(s, "local_radius")
        if "zero_scale" in keys:
            layout.prop(s, "zero_scale")
        if "bulge" in keys or "bulge_range" in keys:
            col = layout.column()
            col.prop(s, "bulge")
            if s.bulge:
                row = col.row()
                row.prop(s, "bulge_range")
                if "bulge" in keys:
                    row.prop(s, "bulge_slope")
                col.prop(s, "bulge_omega")
        self._tree(layout, obj)

    def _as_argument(self, layout, obj):
        parent = obj.parent
        keys = tree.BLEND_KEYS.get(parent.libblend.blend_type, ())
        own = [k for k in ("r", "p", "m") if k in keys]
        box = layout.box()
        args = tree.children(parent)
        box.label(text="Argument %d of %s" % (args.index(obj) + 1, parent.name))
        row = box.row(align=True)
        row.operator("libblend.move_argument", text="Up", icon="TRIA_UP").direction = "UP"
        row.operator("libblend.move_argument", text="Down", icon="TRIA_DOWN").direction = "DOWN"
        if own:
            s = obj.libblend
            box.prop(s, "arg_override")
            if s.arg_override:
                row = box.row(align=True)
                for k in own:
                    row.prop(s, "arg_" + k)
                _note(box, tree.m_note(obj, as_argument=True))


class LIBBLEND_MT_add(bpy.types.Menu):
    bl_label = "libblend"
    bl_idname = "LIBBLEND_MT_add"

    def draw(self, context):
        layout = self.layout
        layout.operator("libblend.add_field", icon="META_BALL")
        layout.operator_menu_enum("libblend.add_primitive", "prim_type", text="Primitive")
        layout.operator_menu_enum("libblend.add_blend", "blend_type", text="Blend")


class LIBBLEND_MT_object(bpy.types.Menu):
    """Object > libblend: every libblend command, so F3 menu search finds them all."""
    bl_label = "libblend"
    bl_idname = "LIBBLEND_MT_object"

    def draw(self, context):
        layout = self.layout
        layout.operator("libblend.update_mesh", text="Update Mesh").final = False
        layout.operator("libblend.update_mesh", text="Update Mesh at Render Resolution").final = True
        layout.operator_menu_enum("libblend.blend_selected", "blend_type", text="Blend Selected")
        layout.operator("libblend.add_bound")
        layout.operator("libblend.bake")
        layout.operator("libblend.bake_clear")
        layout.operator("libblend.apply")
        layout.operator("libblend.move_argument", text="Move Argument Up").direction = "UP"
        layout.operator("libblend.move_argument", text="Move Argument Down").direction = "DOWN"
        layout.separator()
        layout.operator("libblend.import_scene")
        layout.operator("libblend.export_scene")
        layout.operator("libblend.export_pov")
        layout.operator("libblend.reload_library")


def _menu_object(self, context):
    self.layout.menu(LIBBLEND_MT_object.bl_idname)


def _menu_add(self, context):
    self.layout.menu(LIBBLEND_MT_add.bl_idname, icon="META_BALL")


def _menu_import(self, context):
    self.layout.operator("libblend.import_scene", text="libblend Scene (.json)")


def _menu_export(self, context):
    self.layout.operator("libblend.export_scene", text="libblend Scene (.json)")
    self.layout.operator("libblend.export_pov", text="libblend POV-Ray Scene (.pov)")


CLASSES = [LIBBLEND_AP_preferences, LIBBLEND_PT_panel, LIBBLEND_MT_add, LIBBLEND_MT_object]
MENUS = [("VIEW3D_MT_add", _menu_add), ("VIEW3D_MT_object", _menu_object), ("TOPBAR_MT_file_import", _menu_import),
         ("TOPBAR_MT_file_export", _menu_export)]
