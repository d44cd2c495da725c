"""BVH in and out of Blender: Blender's importer made to run on Python 3.11, and a writer.

Why a writer of our own: Blender's exporter writes bones in Blender's Z-up armature space, so a
take imported from a Y-up library and exported again no longer has the library's rest frame, and
the server scores it far from its own source. This writer turns the armature back to the BVH
axes Blender's importer assumes (Y up, -Z forward) before writing rotations and offsets.
"""
import builtins
import contextlib
import math
import re

import bpy
from bpy_extras.io_utils import axis_conversion

# Blender's importer maps BVH axes (-Z forward, Y up) to Blender's (Y forward, Z up); the inverse.
_TO_BVH = axis_conversion(from_forward="Y", from_up="Z", to_forward="-Z", to_up="Y")
# Channels "Zrotation Yrotation Xrotation": R = Rz Ry Rx, mathutils' Euler order "XYZ".
_CHANNEL_ORDER = "ZYX"


@contextlib.contextmanager
def _open_without_u_mode():
    """Debian's Blender 3.4 runs on Python 3.11, which refuses the mode 'rU' its BVH importer
    passes to open(); while this holds, open() drops the 'U'."""
    original = builtins.open

    def open_without_u(file, mode="r", *rest, **options):
        return original(file, mode.replace("U", ""), *rest, **options)

    builtins.open = open_without_u
    try:
        yield
    finally:
        builtins.open = original


def import_bvh(path, **options):
    """Blender's BVH importer (bpy.ops.import_anim.bvh with OPTIONS); the new armature object."""
    with _open_without_u_mode():
        result = bpy.ops.import_anim.bvh(filepath=str(path), **options)
    if "FINISHED" not in result:
        raise RuntimeError(f"Blender's BVH importer could not read {path}")
    return bpy.context.view_layer.objects.active


def frame_time(bvh_text):
    """The "Frame Time:" of a BVH's text, in seconds."""
    match = re.search(r"^\s*Frame Time:\s*([0-9.eE+-]+)", bvh_text, re.M)
    if not match or float(match.group(1)) <= 0:
        raise ValueError("the BVH has no positive Frame Time")
    return float(match.group(1))


def write_bvh(scene, armature, frame_start, frame_end):
    """The armature's poses at frames frame_start..frame_end as BVH text at the scene's rate.

    The root's OFFSET is 0 and its position channels are its head's position, so that readers
    that add the OFFSET and readers that do not agree.
    """
    bones = armature.data.bones
    roots = [bone for bone in bones if bone.parent is None]
    if len(roots) != 1:
        raise ValueError(f"armature '{armature.name}' has {len(roots)} root bones; a BVH "
                         "skeleton has one")
    if frame_end < frame_start:
        raise ValueError(f"the range {frame_start}-{frame_end} is empty")
    order = []  # bones as the hierarchy lists them, each before its children
    lines = ["HIERARCHY"]

    def write_joint(bone, depth):
        order.append(bone)
        pad = "\t" * depth
        offset = (0.0, 0.0, 0.0) if bone.parent is None else \
            _TO_BVH @ (bone.head_local - bone.parent.head_local)
        lines.append(f"{pad}{'JOINT' if bone.parent else 'ROOT'} {bone.name}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}\tOFFSET {_numbers(offset)}")
        rotations = " ".join(f"{axis}rotation" for axis in _CHANNEL_ORDER)
        if bone.parent is None:
            lines.append(f"{pad}\tCHANNELS 6 Xposition Yposition Zposition {rotations}")
        else:
            lines.append(f"{pad}\tCHANNELS 3 {rotations}")
        for child in bone.children:
            write_joint(child, depth + 1)
        if not bone.children:
            lines.extend([f"{pad}\tEnd Site", f"{pad}\t{{",
                          f"{pad}\t\tOFFSET {_numbers(_TO_BVH @ (bone.tail_local - bone.head_local))}",
                          f"{pad}\t}}"])
        lines.append(f"{pad}}}")

    write_joint(roots[0], 0)
    fps = scene.render.fps / scene.render.fps_base
    lines += ["MOTION", f"Frames: {frame_end - frame_start + 1}", f"Frame Time: {1.0 / fps:.8f}"]
    rest_inverse = {bone.name: bone.matrix_local.to_3x3().inverted() for bone in order}
    to_bvh_inverse = _TO_BVH.transposed()
    previous = {}  # each bone's last Euler, so that angles stay continuous
    current = scene.frame_current
    try:
        for frame in range(frame_start, frame_end + 1):
            scene.frame_set(frame)
            world = {}  # each bone's rotation from its rest, in BVH axes
            row = []
            for bone in order:
                pose_bone = armature.pose.bones[bone.name]
                world[bone.name] = _TO_BVH @ (pose_bone.matrix.to_3x3() @ rest_inverse[bone.name]) \
                    @ to_bvh_inverse
                local = world[bone.name] if bone.parent is None else \
                    world[bone.parent.name].transposed() @ world[bone.name]
                euler = local.to_euler(_CHANNEL_ORDER[::-1], *previous.get(bone.name, ()))
                previous[bone.name] = (euler,)
                if bone.parent is None:
                    row.append(_numbers(_TO_BVH @ pose_bone.head))
                row.append(_numbers(math.degrees(getattr(euler, axis.lower()))
                                    for axis in _CHANNEL_ORDER))
            lines.append(" ".join(row))
    finally:
        scene.frame_set(current)
    return "\n".join(lines) + "\n"


def _numbers(values):
    return " ".join(f"{value:.6f}" for value in values)
