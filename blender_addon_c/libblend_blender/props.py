"""Settings stored on Blender objects (saved in the .blend, undoable).

Every libblend object carries Object.libblend (LB_ObjectSettings); `kind`
says what it is:
  OUTPUT     a mesh object: the field's region, resolutions and convention;
             its one child node is the root of the blend tree.
  PRIMITIVE  an empty: one primitive of the scene format; its transform is
             the node's transform (relative to its parent).
  BLEND      an empty: one operator; its children (role ARG, in `order`)
             are its arguments.
A node's own `arg_*` settings are the per-argument r / p / m its parent
blend uses for it (the parent's values unless overridden). A child with role
BOUND is the bounding solid of its parent when that parent is an argument of
a `bounded` blend.
"""
import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty,
                       FloatVectorProperty, IntProperty, PointerProperty, StringProperty)


def _changed(self, context):
    from . import live
    live.mark_dirty(self.id_data)


PRIMITIVES = [
    ("sphere", "Sphere", "|X - c| / radius"),
    ("ellipsoid", "Ellipsoid", "axis-aligned ellipsoid with semi-axes"),
    ("lp", "LP Metric", "(sum |x_i / a_i|^n)^(1/n): a rounded box for large n"),
    ("superquadric", "Super-ellipsoid", "Barr's superquadric, exponents e1, e2"),
    ("slab", "Slab", "between two parallel planes"),
    ("halfspace", "Half-space", "one side of a plane"),
    ("cylinder", "Cylinder", "infinite cylinder around an axis"),
    ("capsule", "Capsule", "distance to a segment"),
    ("torus", "Torus", "distance to a circle"),
]
BLENDS_ZERO = [
    ("displacement", "Displacement BT_k", "k-ary hyper-ellipsoidal blend (r, p, m per argument)"),
    ("conic", "Conic BT_2", "binary conic blend, closed form"),
    ("scale", "Scale (Hsu-Lee)", "scale-method blend"),
    ("bounded", "Bounded", "blend limited by a bounding solid per argument"),
    ("rfunction", "R-function", "Rvachev union / intersection"),
]
#: both conventions, the sharp operations
BLENDS_SHARP = [
    ("min", "Min (sharp union)", "min of the arguments"),
    ("max", "Max (sharp intersection)", "max of the arguments"),
    ("complement", "Complement", "-f"),
]
BLENDS_SOFT = [
    ("soft_hyper", "Soft Hyper", "super-ellipsoidal k-ary soft blend (non-uniform scaling)"),
    ("soft_conic", "Soft Conic", "binary conic soft blend (non-uniform scaling)"),
    ("soft_sum", "Soft Sum", "Wyvill's sum"),
    ("ricci", "Ricci", "Ricci's union (sum x^n)^(1/n)"),
    ("perlin", "Perlin", "Perlin's products"),
]
#: both conventions
BLENDS_BOTH = [
    ("local_union", "Local Union", "blends only around the intersection curves (Bernhardt et al. "
     "2010): the exact union elsewhere"),
    ("clean_union", "Clean Union", "the exact union surface, C1 elsewhere, no blend"),
    ("level", "Level", "its argument's level set at Level is the surface (zero: an offset "
     "surface; soft: another threshold)"),
]
#: the order saved .blend files number the items by (an enum stores a position)
BLENDS = BLENDS_ZERO + BLENDS_SHARP + BLENDS_SOFT + BLENDS_BOTH
OPS = [("union", "Union", ""), ("intersection", "Intersection", ""),
       ("difference", "Difference", "the first argument minus the others")]


class LB_ObjectRef(bpy.types.PropertyGroup):
    obj: PointerProperty(type=bpy.types.Object)


class LB_ObjectSettings(bpy.types.PropertyGroup):
    kind: EnumProperty(name="Kind", items=[
        ("NONE", "None", ""), ("OUTPUT", "Field Output", ""),
        ("PRIMITIVE", "Primitive", ""), ("BLEND", "Blend", "")], default="NONE")
    role: EnumProperty(name="Role", items=[
        ("ARG", "Argument", "an argument of the parent blend"),
        ("BOUND", "Bounding Solid", "the bounding solid of the parent (bounded blends)")],
        default="ARG", update=_changed)
    order: IntProperty(name="Order", description="position among the parent's arguments",
                       update=_changed)

    # ---- output
    convention: EnumProperty(name="Convention", items=[
        ("zero", "Zero (distance-like)", "inside f < 0, surface f = 0"),
        ("soft", "Soft (kernels)", "inside f > 0.5, surface f = 0.5")], update=_changed)
    fit_region: BoolProperty(name="Fit Region", description="mesh in a box fitted to the field "
                             "(libblend's interval bounds of the solid, grown by a margin, found "
                             "again whenever the tree changes); off: the Region Min / Max box. On "
                             "for fields made with Add, off for imported scenes (their bounds)",
                             default=False, update=_changed)
    bounds_min: FloatVectorProperty(name="Region Min", default=(-2, -2, -2), subtype="XYZ",
                                    update=_changed)
    bounds_max: FloatVectorProperty(name="Region Max", default=(2, 2, 2), subtype="XYZ",
                                    update=_changed)
    preview_resolution: IntProperty(name="Viewport", description="cells along the region's "
                                    "longest side in the viewport", default=64, min=4,
                                    soft_max=256, max=2048, update=_changed)
    render_resolution: IntProperty(name="Render", description="cells along the region's longest "
                                   "side for final renders and Apply", default=160, min=4,
                                   soft_max=512, max=8192)
    live: BoolProperty(name="Live Update", description="remesh when a setting or a primitive's "
                       "transform changes", default=True, update=_changed)
    open_boundary: BoolProperty(name="Open at Region", description="leave the mesh open where the "
                                "region cuts the solid", default=False, update=_changed)
    sharp_features: BoolProperty(name="Sharp Features", description="keep creases and corners "
                                 "(min, max, clean and local unions, slabs) sharp: a vertex on "
                                 "each crease, and a split normal per side so it shades sharp. "
                                 "Costs up to 1.8x the meshing time on scenes with many creases",
                                 default=False, update=_changed)
    simplify: FloatProperty(name="Simplify", description="fewer triangles where the surface "
                            "allows: merge triangles wherever the mesh stays within this many "
                            "cells of the field, never across a crease (with Sharp Features a "
                            "flat face becomes a few large triangles). 0 = off", default=0.0,
                            min=0.0, max=1.0, step=5, precision=2, update=_changed)
    simplify_method: EnumProperty(name="Method", items=[
        ("COLLAPSE", "Collapse", "mesh, then merge triangles: the fewest triangles, at several "
         "times the meshing time (bakes and renders)"),
        ("COARSE", "Coarse First", "mesh cells of twice the size wherever the surface stays "
         "within the tolerance: more triangles than Collapse for far less time (live "
         "updates). With Sharp Features, Collapse is used")],
        default="COLLAPSE", update=_changed)
    merge_flat: BoolProperty(name="Merge Flat", description="flat faces (a box's sides, a "
                             "slab's, a cylinder's caps) as few large triangles, the surface "
                             "unchanged: fewer triangles for Blender to take in", default=False,
                             update=_changed)
    normals: EnumProperty(name="Normals", items=[
        ("AUTO", "Auto", "analytic normals below 250k triangles, Blender's smooth normals above"),
        ("ANALYTIC", "Analytic", "libblend's exact normals as custom split normals"),
        ("FACES", "Blender", "Blender's smooth normals from the faces (fastest)")],
        default="AUTO", update=_changed)
    use_bake: BoolProperty(name="Use Baked Cache", description="renders and frame changes read "
                           "each frame's mesh from the bake folder (frames not baked, or "
                           "changed since, are meshed)", default=False, update=_changed)
    bake_dir: StringProperty(name="Bake Folder", subtype="DIR_PATH", description="where Bake "
                             "writes one file per frame (empty: //libblend_cache/<field name>/, "
                             "next to the .blend)")
    bake_info: StringProperty(name="Baked", description="what the last bake wrote")
    render_camera: PointerProperty(type=bpy.types.Object, name="Camera", description="the "
                                   "camera exported as the scene's render camera")
    render_lights: CollectionProperty(type=LB_ObjectRef, name="Lights", description="the lights "
                                      "exported as the scene's render lights")
    title: StringProperty(name="Title")
    description: StringProperty(name="Description")
    render_json: StringProperty(name="Render Section", description="the scene file's render "
                                "section (camera, lights, material), kept for export")

    # ---- primitive
    prim_type: EnumProperty(name="Primitive", items=PRIMITIVES, update=_changed)
    center: FloatVectorProperty(name="Center", subtype="XYZ", update=_changed,
                                description="centre (point on the plane / axis)")
    axis: FloatVectorProperty(name="Axis", default=(0, 0, 1), subtype="XYZ", update=_changed,
                              description="axis or normal direction")
    radius: FloatProperty(name="Radius", default=1.0, min=1e-9, update=_changed)
    semi_axes: FloatVectorProperty(name="Semi-axes", default=(1, 1, 1), min=1e-9, update=_changed)
    exponent: FloatProperty(name="Exponent", default=4.0, min=1.0, max=1000.0, update=_changed)
    e1: FloatProperty(name="e1", default=1.0, min=0.01, max=10.0, update=_changed)
    e2: FloatProperty(name="e2", default=1.0, min=0.01, max=10.0, update=_changed)
    half_width: FloatProperty(name="Half Width", default=1.0, min=1e-9, update=_changed)
    width: FloatProperty(name="Width", default=1.0, min=1e-9, update=_changed)
    major_radius: FloatProperty(name="Major Radius", default=1.0, min=1e-9, update=_changed)
    minor_radius: FloatProperty(name="Minor Radius", default=0.25, min=1e-9, update=_changed)
    start: FloatVectorProperty(name="Start", default=(0, 0, -1), subtype="XYZ", update=_changed)
    end: FloatVectorProperty(name="End", default=(0, 0, 1), subtype="XYZ", update=_changed)
    kernel: EnumProperty(name="Kernel", items=[("wyvill", "Wyvill", ""), ("blinn", "Blinn", "")],
                         update=_changed)

    # ---- blend
    blend_type: EnumProperty(name="Operator", items=BLENDS, update=_changed)
    op: EnumProperty(name="Set Operation", items=OPS, update=_changed)
    r: FloatProperty(name="Range r", description="blending range (per argument unless "
                     "overridden)", default=0.3, min=1e-9, soft_max=10.0, update=_changed)
    p: FloatProperty(name="Curvature p", description="curvature exponent > 1 (2 = fast closed "
                     "form)", default=2.0, min=1.0001, max=1000.0, update=_changed)
    m: FloatProperty(name="Subsequent m", description="reach of this blend on later blends "
                     "(1 = the classic operator)", default=1.0, min=1e-6, max=1e6,
                     soft_min=0.05, soft_max=5, update=_changed)
    conic_p: FloatProperty(name="Conic p", description="conic shape, below r1 r2 (0 = quarter "
                           "ellipse)", default=0.0, update=_changed)
    ricci_n: FloatProperty(name="n", default=2.0, min=1.0, max=1000.0, update=_changed)
    level: FloatProperty(name="Level", description="the argument's level set taken as the "
                         "surface (zero convention: any value, an offset surface; soft: in (0, 1))",
                         default=0.0, soft_min=-1.0, soft_max=1.0, update=_changed)
    bulge: BoolProperty(name="Bulge Elimination", default=False, update=_changed)
    bulge_range: BoolProperty(name="Range", default=True, update=_changed)
    bulge_slope: BoolProperty(name="Slope", default=False, update=_changed)
    bulge_omega: FloatProperty(name="Omega", default=0.001, min=1e-6, max=1.0, precision=4,
                               update=_changed)

    local_exponent: FloatProperty(name="Exponent n", description="beta = v^n inside the blending "
                                  "volume", default=2.0, min=1.0, max=1000.0, update=_changed)
    local_support: EnumProperty(name="Support", items=[
        ("progressive", "Progressive", "R = support factor x the intersection curve's diameter"),
        ("feature", "Feature", "R = 2 min(d1, d2)")], update=_changed)
    local_support_factor: FloatProperty(name="Support Factor", default=0.25, min=1e-3, max=100.0,
                                        update=_changed)
    local_radius: FloatProperty(name="Radius R", description="the blending volume's support "
                                "(0 = automatic)", default=0.0, min=0.0, update=_changed)
    zero_scale: FloatProperty(name="Zero Scale", description="zero convention: the children "
                              "enter as 0.5 (1 - f / zero_scale)", default=1.0, min=1e-9,
                              max=1e9, update=_changed)
    local_extra: StringProperty(name="More Keys", description="feature_size, limits and alpha "
                                "of the scene file, kept for export (JSON)", update=_changed)

    # ---- this node's own material (the scene file's "material" on the node)
    has_material: BoolProperty(name="Own Material", description="this node's surface (and what "
                               "it decides below it) takes its own colour and finish",
                               default=False, update=_changed)
    material_color: FloatVectorProperty(name="Colour", subtype="COLOR", size=3, min=0.0, max=1.0,
                                        default=(0.8, 0.8, 0.8), update=_changed)
    material_specular: FloatProperty(name="Specular", min=0.0, max=1.0, default=0.3,
                                     update=_changed)
    material_extra: StringProperty(name="Kept Finish", description="ambient and diffuse of the "
                                   "scene file's material, kept for export (JSON)",
                                   update=_changed)

    # ---- this node as an argument of its parent blend
    arg_override: BoolProperty(name="Own r / p / m", description="use this argument's own "
                               "r, p, m instead of the parent blend's", update=_changed)
    arg_r: FloatProperty(name="r", default=0.3, min=1e-9, soft_max=10.0, update=_changed)
    arg_p: FloatProperty(name="p", default=2.0, min=1.0001, max=1000.0, update=_changed)
    arg_m: FloatProperty(name="m", default=1.0, min=1e-6, max=1e6, soft_min=0.05, soft_max=5,
                         update=_changed)


def register():
    bpy.utils.register_class(LB_ObjectRef)
    bpy.utils.register_class(LB_ObjectSettings)
    bpy.types.Object.libblend = PointerProperty(type=LB_ObjectSettings)


def unregister():
    del bpy.types.Object.libblend
    bpy.utils.unregister_class(LB_ObjectSettings)
    bpy.utils.unregister_class(LB_ObjectRef)
