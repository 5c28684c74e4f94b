"""One Blender, one image: the baseline of bench_farm.py. Run as
    blender -b --factory-startup --python render_one.py -- ADDON_DIR REQUEST.json
it enables the add-on from ADDON_DIR, renders REQUEST (the worker's request
format, libblend_blender/farm_worker.py) with the worker's own code, and
writes the reply to REQUEST.json.reply: what a farm does when it starts
Blender once per frame."""
import importlib
import json
import sys

import bpy

addon, req_path = sys.argv[sys.argv.index("--") + 1:][:2]
sys.path.insert(0, addon)
fw = importlib.import_module("libblend_blender.farm_worker")
reply = fw.render(bpy, fw._package(), json.load(open(req_path)))
json.dump(reply, open(req_path + ".reply", "w"))
