"""A scene file's render section (camera, lights, material;
docs/scene-format.md) as Blender objects, and back.

Import (create): the camera becomes a camera object looking at `look_at`
with the scene's horizontal field of view, made the scene's camera; each
light a sun lamp at its location aimed at the region's centre (POV-Ray's
point lights do not fade with distance; a sun does not either); the
material a Principled BSDF on the field with the section's colour and
specular. The field keeps the objects it made (render_camera,
render_lights) and the section itself (render_json: keys Blender has no
place for, such as ambient and diffuse, and the values as written).

Export (to_section): the section as the objects now say. A camera, light or
material nobody changed since import is written exactly as it was read
(Blender stores float32 and a camera's orientation, not its look_at point);
a changed one is written from the object. Deleted objects drop out.

Conventions: scenes are right-handed with z up, as Blender is. The camera
looks at `look_at` with its up direction along the section's `up` (default
+z); `blendtool pov` writes the same camera for POV-Ray with `sky` up and a
negated `right`, so both render the same right-handed view
(tests/blender/test_addon.py compares their silhouettes). Without lights in
the section both exporters light the field the same three-point way (key
with soft shadows, fill, rim, placed around the camera), over a floor under
the surface (`floor`, default on) and a neutral background (`background`).
"""
import json
import math

import bpy
from mathutils import Matrix, Vector

from . import compat, libhandle, tree

# How an imported render section looks in Cycles as it does in POV-Ray (the
# POV-Ray writer: `assumed_gamma 1`, so the scene's colours are linear in
# both and need no conversion; POV-Ray lights a surface by colour x (ambient
# + diffuse x sum of light x cos), with the scenes' default finish ambient
# 0.1, diffuse 0.7): a POV-Ray light of colour 1 becomes a sun whose
# irradiance on a Lambert surface of the same colour gives the diffuse term
# (pi x 0.7 W/m^2); the background is seen by the camera only, and lights
# the scene at the ambient level; the floor is a Lambert (Diffuse BSDF)
# surface, as POV-Ray's; the view transform is Standard (plain sRGB, as
# POV-Ray's PNG). Measured: the mean luminance of a Cycles render of an
# imported shipped scene within 10 % of the POV-Ray render's
# (tests/blender/test_addon.py, "the look"); it was 1.3x with Filmic, a
# world lighting everything at the background's 0.9 and suns of 3 W/m^2.
POV_DIFFUSE, POV_AMBIENT = 0.7, 0.1
SUN_STRENGTH = math.pi * POV_DIFFUSE  # W/m^2 of a sun for a POV-Ray light of colour 1


def _centre(output):
    s = output.libblend
    return output.matrix_world @ ((Vector(s.bounds_min) + Vector(s.bounds_max)) / 2)


def _aim(obj, target, up="Y"):
    d = Vector(target) - obj.location
    if d.length == 0:
        return
    # looking along the up axis itself: take z as up instead
    axis = {"Y": Vector((0, 1, 0)), "Z": Vector((0, 0, 1))}[up]
    if abs(d.normalized().dot(axis)) > 0.999:
        up = "Z" if up == "Y" else "Y"
    obj.rotation_mode = "QUATERNION"
    obj.rotation_quaternion = d.to_track_quat("-Z", up)


def _aim_up(obj, target, up):
    """Point obj's -z at target with its +y as close to up as possible (a
    camera: +x is then the image's right, forward x up)."""
    d = Vector(target) - obj.location
    if d.length == 0:
        return
    d.normalize()
    x = d.cross(Vector(up))
    if x.length < 1e-9:  # up along the line of sight (the scene parser refuses this)
        x = d.orthogonal()
    x.normalize()
    y = x.cross(d)
    obj.rotation_mode = "QUATERNION"
    obj.rotation_quaternion = Matrix((x, y, -d)).transposed().to_quaternion()


def camera_basis(location, look_at, up):
    """(forward, right, up) unit vectors of a camera, right-handed."""
    f = (Vector(look_at) - Vector(location)).normalized()
    r = f.cross(Vector(up)).normalized()
    return f, r, r.cross(f)



def _same_vec(a, b, tol=1e-6):
    return len(a) == len(b) and all(abs(x - y) <= tol * max(1.0, abs(y)) for x, y in zip(a, b))


def create(output, section, collection, scene):
    """Make the section's camera, lights and material for output."""
    s = output.libblend
    s.render_lights.clear()
    cam = section.get("camera")
    if cam:
        data = bpy.data.cameras.new(output.name + " camera")
        data.lens_unit = "FOV"
        data.sensor_fit = "HORIZONTAL"
        data.angle = math.radians(cam.get("angle", 40))
        obj = bpy.data.objects.new(output.name + " camera", data)
        collection.objects.link(obj)
        obj.location = cam["location"]
        _aim_up(obj, cam.get("look_at", [0, 0, 0]), cam.get("up", [0, 0, 1]))
        data.clip_end = max(data.clip_end, 4 * (Vector(cam["location"]) - _centre(output)).length)
        s.render_camera = obj
        scene.camera = obj
    for i, li in enumerate(section.get("lights", [])):
        data = bpy.data.lights.new("%s light %d" % (output.name, i + 1), "SUN")
        c = li.get("color", [1, 1, 1])
        k = max(1.0, max(c))
        data.color = [v / k for v in c]
        data.energy = SUN_STRENGTH * k
        data.angle = 0.0
        obj = bpy.data.objects.new(data.name, data)
        collection.objects.link(obj)
        obj.location = li["location"]
        _aim(obj, _centre(output), "Z")
        s.render_lights.add().obj = obj
    if cam and not section.get("lights"):
        _three_point(output, cam, collection)
    if section.get("floor", True) is not False:
        _floor(output, section, collection)
    _world(scene, section.get("background", [0.9, 0.9, 0.9]))
    scene.view_settings.view_transform = "Standard"
    mat = section.get("material")
    if mat:
        m = bpy.data.materials.new(output.name + " material")
        m.use_nodes = True
        bsdf = m.node_tree.nodes.get("Principled BSDF")
        names = compat.principled_inputs()
        c = mat.get("color", [0.8, 0.8, 0.8])
        bsdf.inputs[names["color"]].default_value = list(c) + [1.0]
        bsdf.inputs[names["specular"]].default_value = mat.get("specular", 0.0)
        bsdf.inputs[names["roughness"]].default_value = 0.4
        m.diffuse_color = list(c) + [1.0]  # the viewport's solid colour
        output.data.materials.clear()
        output.data.materials.append(m)


def _world(scene, bg):
    """The background seen by the camera; everything else sees the ambient
    level (POV-Ray's background lights nothing)."""
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.color = bg  # the viewport's
    world.use_nodes = True
    nt = world.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    out = nt.nodes.new("ShaderNodeOutputWorld")
    seen = nt.nodes.new("ShaderNodeBackground")
    seen.inputs["Color"].default_value = list(bg) + [1.0]
    lit = nt.nodes.new("ShaderNodeBackground")
    lit.inputs["Color"].default_value = [POV_AMBIENT] * 3 + [1.0]
    path = nt.nodes.new("ShaderNodeLightPath")
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(path.outputs["Is Camera Ray"], mix.inputs[0])
    nt.links.new(lit.outputs["Background"], mix.inputs[1])
    nt.links.new(seen.outputs["Background"], mix.inputs[2])
    nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])


def _three_point(output, cam, collection):
    """The default lights around the camera (libblend's
    lb_render_three_point, the POV-Ray writer's too), as suns aimed at the
    camera's target; the key's 5 degree disc gives soft shadows. They are
    not the section's lights: export leaves "lights" out, as read."""
    at = cam.get("look_at", [0, 0, 0])
    lights = libhandle.library().three_point(cam["location"], at, cam.get("up", [0, 0, 1]))
    for i, (location, strength, shadows) in enumerate(lights):
        data = bpy.data.lights.new("%s %s light" % (output.name, ("key", "fill", "rim")[i]), "SUN")
        data.energy = SUN_STRENGTH * strength
        data.angle = math.radians(5.0) if shadows else 0.0
        data.use_shadow = shadows
        obj = bpy.data.objects.new(data.name, data)
        collection.objects.link(obj)
        obj.location = location
        _aim(obj, at, "Z")


def floor_height(output, up):
    """The floor's height along up (world): libblend's lb_render_floor_height
    (as the POV-Ray writer) over the field's region, with up taken into the
    field's frame, or the region's lowest corner when the tree is broken."""
    from . import live
    M = output.matrix_world
    bmin, bmax = live.region_of(output)
    corners = [Vector((x, y, z)) for x in (bmin[0], bmax[0])
               for y in (bmin[1], bmax[1]) for z in (bmin[2], bmax[2])]
    h = min((M @ c).dot(Vector(up)) for c in corners)
    # up . (A p + t) = (A^T up) . p + up . t
    local_up = M.to_3x3().transposed() @ Vector(up)
    try:
        text, _paths, bmin, bmax, _cell = live.scene_text(output, render=False)
        with libhandle.library().parse_scene(text, output.name + ".json") as sc, sc.compile() as ev:
            return ev.floor_height(bmin, bmax, local_up, libhandle.threads()) + \
                M.translation.dot(Vector(up))
    except Exception:  # no library or a tree error: the region's corner, as documented
        return h


def _floor(output, section, collection):
    """A large plane under the field (floor_height) with the section's
    floor colour."""
    up = Vector(section.get("camera", {}).get("up", [0, 0, 1])).normalized()
    h = floor_height(output, up)
    from . import live
    bmin, bmax = live.region_of(output)
    size = 20.0 * max((Vector(bmax) - Vector(bmin)).length, 1e-3)
    me = bpy.data.meshes.new(output.name + " floor")
    me.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
    obj = bpy.data.objects.new(output.name + " floor", me)
    collection.objects.link(obj)
    obj.scale = (size, size, 1)
    obj.rotation_mode = "QUATERNION"
    obj.rotation_quaternion = Vector((0, 0, 1)).rotation_difference(up)
    obj.location = up * h
    fl = section.get("floor")
    col = fl.get("color", [0.75] * 3) if isinstance(fl, dict) else [0.75] * 3
    m = bpy.data.materials.new(output.name + " floor")
    m.use_nodes = True
    nt = m.node_tree
    m.node_tree.nodes["Principled BSDF"].inputs[compat.principled_inputs()["color"]] \
        .default_value = list(col) + [1.0]
    lambert = nt.nodes.new("ShaderNodeBsdfDiffuse")  # POV-Ray's floor: diffuse, no highlight
    lambert.inputs["Color"].default_value = list(col) + [1.0]
    out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
    nt.links.new(lambert.outputs["BSDF"], out.inputs["Surface"])
    m.diffuse_color = list(col) + [1.0]
    me.materials.append(m)


def _alive(obj):
    try:
        return obj is not None and obj.name in bpy.data.objects
    except ReferenceError:
        return False


def to_section(output):
    """The render section for export (a dict), or None when there is none."""
    s = output.libblend
    try:
        stored = json.loads(s.render_json) if s.render_json else {}
    except ValueError:
        raise tree.TreeError("field '%s': its stored render section is not JSON; clear it in the "
                             "panel" % output.name) from None
    made = bool(s.render_camera) or len(s.render_lights) > 0
    out = {k: v for k, v in stored.items() if k not in ("camera", "lights", "material")}
    # camera
    cam = s.render_camera if _alive(s.render_camera) and s.render_camera.type == "CAMERA" else None
    old = stored.get("camera")
    if cam is not None:
        loc = tree.vec(cam.matrix_world.translation)
        q = cam.matrix_world.to_quaternion()
        fwd = (q @ Vector((0, 0, -1))).normalized()
        cup = (q @ Vector((0, 1, 0))).normalized()
        angle = math.degrees(cam.data.angle_x)
        if old and _same_vec(loc, old["location"]) and abs(angle - old.get("angle", 40)) < 1e-4:
            target = Vector(old.get("look_at", [0, 0, 0])) - Vector(old["location"])
            # the same up: the stored one, made perpendicular to the line of sight
            # (tolerances of 1e-6: mathutils computes in float32)
            want = (camera_basis(old["location"], old.get("look_at", [0, 0, 0]),
                                 old.get("up", [0, 0, 1]))[2] if target.length else cup)
            if target.length == 0 or (fwd.dot(target.normalized()) > 1 - 1e-6 and
                                      cup.dot(want) > 1 - 1e-6):
                cam = None
                out["camera"] = old
        if cam is not None:
            dist = (Vector(old.get("look_at", [0, 0, 0])) - Vector(old["location"])).length \
                if old else (_centre(output) - cam.matrix_world.translation).length
            out["camera"] = {"location": loc,
                             "look_at": tree.vec(cam.matrix_world.translation + fwd * max(dist, 1e-3)),
                             "up": tree.vec(cup), "angle": tree.f32(angle)}
    elif old and not made:
        out["camera"] = old
    # lights
    old_lights = stored.get("lights", [])
    lights = []
    refs = [r.obj for r in s.render_lights if _alive(r.obj) and r.obj.type == "LIGHT"]
    for i, obj in enumerate(refs):
        loc = tree.vec(obj.matrix_world.translation)
        col = tree.vec([c * obj.data.energy / SUN_STRENGTH for c in obj.data.color])
        prev = old_lights[i] if i < len(old_lights) else None
        if prev and _same_vec(loc, prev["location"]) and _same_vec(col, prev.get("color", [1, 1, 1])):
            lights.append(prev)
        else:
            lights.append({"location": loc, "color": col})
    if refs or (old_lights and not made):
        out["lights"] = lights if refs else old_lights
    # material
    old_mat = stored.get("material")
    m = output.active_material
    bsdf = m.node_tree.nodes.get("Principled BSDF") if m and m.use_nodes and m.node_tree else None
    if bsdf is not None:
        names = compat.principled_inputs()
        col = tree.vec(bsdf.inputs[names["color"]].default_value[:3])
        spec = tree.f32(bsdf.inputs[names["specular"]].default_value)
        mat = dict(old_mat or {})
        if not (old_mat and _same_vec(col, old_mat.get("color", [0.8, 0.8, 0.8]))):
            mat["color"] = col
        if not (old_mat and abs(spec - old_mat.get("specular", 0.0)) < 1e-6):
            mat["specular"] = min(1.0, max(0.0, spec))
        out["material"] = mat
    elif old_mat:
        out["material"] = old_mat
    return out or None
