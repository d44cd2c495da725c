"""motiondb in Blender: search the library with the active action, import hits, label, ingest.

The sidebar's motiondb tab (N) in the 3-D viewport and the dope sheet; the server's URL, token
and TLS CA in the add-on's preferences. Talks to the server's HTTP/JSON API with Python's
standard library only.
"""
import bpy

from . import operators, ui

bl_info = {
    "name": "motiondb",
    "author": "motiondb",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "3D Viewport and Dope Sheet > Sidebar > motiondb",
    "description": "Search a motiondb server with the active action, import hits, label ranges",
    "category": "Animation",
}

_classes = ui.classes + operators.classes


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    ui.register_properties()


def unregister():
    if bpy.app.timers.is_registered(operators.follow_job):
        bpy.app.timers.unregister(operators.follow_job)
    ui.unregister_properties()
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
