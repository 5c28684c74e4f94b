"""The add-on zip installs the way a user installs it (Preferences > Add-ons >
Install) and works from the installed copy, with its bundled library:

    BLENDER_USER_SCRIPTS=DIR blender -b --factory-startup --python-exit-code 1 \
        --python test_install_zip.py -- ZIP
"""
import os
import sys

import addon_utils
import bpy

zip_path = sys.argv[sys.argv.index("--") + 1]
scripts = os.environ["BLENDER_USER_SCRIPTS"]
os.environ.pop("LIBBLEND_LIBRARY", None)
res = bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
assert res == {"FINISHED"}, res
installed = os.path.join(scripts, "addons", "libblend_blender")
assert os.path.isfile(os.path.join(installed, "lib", "libblend.so")), "library installed with it"
assert os.path.isfile(os.path.join(installed, "povray", "libblend.inc")), "libblend.inc installed"
mod = addon_utils.enable("libblend_blender", default_set=True)
assert mod is not None and os.path.dirname(mod.__file__) == installed, mod
from libblend_blender import live  # noqa: E402

ok, msg = live.library_status()
assert ok and live.library().path.startswith(installed), msg
assert bpy.ops.libblend.add_field() == {"FINISHED"}
out = bpy.context.view_layer.objects.active
assert len(out.data.polygons) > 1000, "the default sphere is meshed"
addon_utils.disable("libblend_blender")
print("test_install_zip: installed from %s, %d triangles" % (os.path.basename(zip_path),
                                                          len(out.data.polygons)))
