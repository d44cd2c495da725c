"""Makes FBX and glTF test files from BVH with Blender, as a studio's tools would.

blender -b --factory-startup --python bvh_to_scene.py -- OUT_BASE BVH [BVH...] [--up Z] [--formats fbx,glb]

Writes OUT_BASE.fbx and/or OUT_BASE.glb: the first BVH's skeleton and motion at the BVH's own
frame rate; each further BVH (same skeleton) another take of the FBX. --up Z writes a Z-up FBX.
Without a BVH: a cube and no animation, a file without a skeleton.
"""
import pathlib
import sys

import bpy

# The Blender add-on's importer, which works around Debian's Blender 3.4 BVH importer on Python
# 3.11 (client/blender/motiondb_blender/bvh_io.py).
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "client" / "blender"))
from motiondb_blender.bvh_io import import_bvh as import_bvh_file  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:]
up = "Y"
formats = ["fbx", "glb"]
if "--up" in args:
    i = args.index("--up")
    up = args[i + 1]
    del args[i:i + 2]
if "--formats" in args:
    i = args.index("--formats")
    formats = args[i + 1].split(",")
    del args[i:i + 2]
out_base, sources = args[0], args[1:]

def import_bvh(path):
    return import_bvh_file(path, update_scene_fps=True, update_scene_duration=True)


bpy.ops.wm.read_factory_settings(use_empty=True)
if not sources:
    bpy.ops.mesh.primitive_cube_add()
    if "fbx" in formats:
        bpy.ops.export_scene.fbx(filepath=out_base + ".fbx")
    if "glb" in formats:
        bpy.ops.export_scene.gltf(filepath=out_base + ".glb", export_format="GLB")
    sys.exit(0)
armature = import_bvh(sources[0])
first_action = armature.animation_data.action
first_action.use_fake_user = True
for source in sources[1:]:
    other = import_bvh(source)
    action = other.animation_data.action
    action.use_fake_user = True
    bpy.data.objects.remove(other)
    armature.animation_data.action = first_action

start, end = first_action.frame_range
bpy.context.scene.frame_start, bpy.context.scene.frame_end = int(start), int(end)
bpy.ops.object.select_all(action="DESELECT")
armature.select_set(True)
bpy.context.view_layer.objects.active = armature
if "fbx" in formats:
    bpy.ops.export_scene.fbx(filepath=out_base + ".fbx", use_selection=True,
                             add_leaf_bones=False, bake_anim=True,
                             bake_anim_use_all_actions=True,
                             bake_anim_use_nla_strips=False, bake_anim_simplify_factor=0.0,
                             axis_up=up, axis_forward="-Y" if up == "Z" else "-Z")
if "glb" in formats:
    bpy.ops.export_scene.gltf(filepath=out_base + ".glb", export_format="GLB",
                              use_selection=True, export_animations=True,
                              export_force_sampling=True, export_nla_strips=False)
