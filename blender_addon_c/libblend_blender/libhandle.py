"""The add-on's one handle on the libblend library and its preferences.

Every module that calls the library (live meshing, the render section's
lights and floor, the operators, the panels) takes it from here, so no
module has to import live.py for it: the import graph stays a tree (live ->
tree -> render_section -> libhandle). The library is loaded on first use
from the path in the add-on's preferences, or the copy shipped in lib/; a
failure is kept, with its reason, until reload_library(), so every panel and
operator can show the same message."""
import os

import bpy

from . import binding

_lib = None
_lib_error = None


def prefs():
    """The add-on's preferences, or None while it is not enabled."""
    addon = bpy.context.preferences.addons.get(__package__)
    return addon.preferences if addon else None


def library():
    """The loaded library; raises binding.LibraryError with the reason."""
    global _lib, _lib_error
    if _lib is None and _lib_error is None:
        p = prefs()
        path = (p.library_path if p and p.library_path else None)
        try:
            _lib = binding.load(bpy.path.abspath(path) if path else None)
        except binding.LibraryError as e:
            _lib_error = e
    if _lib is None:
        raise _lib_error
    return _lib


def library_status():
    """(ok, text) for the UI."""
    try:
        lib = library()
        return True, "libblend %d.%d.%d (%s)" % (lib.version + (os.path.basename(lib.path),))
    except binding.LibraryError as e:
        return False, str(e)


def reload_library():
    """Forget the loaded library (or its failure) and load it again."""
    global _lib, _lib_error
    _lib, _lib_error = None, None
    return library_status()


def threads():
    """Threads for meshing and evaluation (0: one per CPU)."""
    p = prefs()
    return p.threads if p else 0


VIEWPORT_SIMPLIFY = 0.5  # the Viewport Simplify preference's default (ui.py), cells


def viewport_simplify():
    """The Viewport Simplify preference, cells (0: off)."""
    p = prefs()
    return p.viewport_simplify if p else VIEWPORT_SIMPLIFY
