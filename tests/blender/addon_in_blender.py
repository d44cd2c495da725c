"""The add-on's checks, run inside Blender by blender_addon_test.py:

    blender -b --factory-startup --python-exit-code 1 --python addon_in_blender.py -- \
        ZIP SERVER_URL TOKEN_FILE TLS_CA TAKE_BVH DEAD_URL OUT_PNG

Installs the add-on from ZIP and enables it; checks that its panels are registered in the 3-D
viewport's and the dope sheet's sidebars (-b cannot draw them); connects over HTTPS with the
token file and the CA; loads TAKE_BVH (frames 0-479 of clip 1) through the add-on's importer;
searches with the preview range 100-300, with Mirror (some hits mirrored), then without, and
expects hit 1 to be that range of clip 1; imports hit 1 at frame 500 onto the take's armature
and checks its frame count and four joints' rotations at three frames against the hit's BVH as
the server exports it; imports the whole clip while a one-bone armature is active and expects a
new armature; labels the selected keys, frames 520-600, finds the label through the API at the
clip's frames and in the hits; propagates it and follows the job to its end; ingests the active
action and the take's file; a typed bad token, a missing token file, no CA for the server's
certificate, plain HTTP to its HTTPS port, a dead server, a URL without a scheme and no selected
keys give readable errors; renders the armatures with the workbench engine to OUT_PNG. Any
failed check raises, which --python-exit-code turns into exit 1.
"""
import json
import math
import ssl
import sys
import time
import urllib.request

import addon_utils
import bpy
from bpy_extras.io_utils import axis_conversion
from mathutils import Matrix

zip_path, url, token_file, tls_ca, take_path, dead_url, out_png = \
    sys.argv[sys.argv.index("--") + 1:]
TOKEN = open(token_file).read().strip()
JOINTS = ("Hips", "LeftUpLeg", "RightForeArm", "Head")


def check(condition, what):
    if not condition:
        raise AssertionError(what)
    print(f"ok: {what}")


def api(path):
    """GET a route of the server's API (independently of the add-on's client)."""
    request = urllib.request.Request(url + path, headers={"Authorization": f"Bearer {TOKEN}"})
    with urllib.request.urlopen(request, timeout=60,
                                context=ssl.create_default_context(cafile=tls_ca)) as answer:
        return answer.read()


def operator_error(operator, **options):
    """The message an operator reports when it fails (bpy.ops raises it as RuntimeError)."""
    try:
        result = operator(**options)
    except RuntimeError as error:
        return str(error)
    raise AssertionError(f"{operator.idname_py()} succeeded ({result}); an error was expected")


def bvh_global_rotations(text):
    """Each frame's joint rotations from their rest, in the BVH's axes: {joint: [Matrix, ...]}."""
    tokens = text.split()
    joints, stack, channels = [], [], []  # channels: (joint index, channel name)
    i = tokens.index("HIERARCHY") + 1
    while tokens[i] != "MOTION":
        word = tokens[i]
        if word in ("ROOT", "JOINT"):
            joints.append((tokens[i + 1], stack[-1] if stack else None))
            i += 2
        elif word == "End":
            i += 2
            depth = 0
            while True:  # skip the End Site's braces
                depth += {"{": 1, "}": -1}.get(tokens[i], 0)
                i += 1
                if depth == 0:
                    break
            continue
        elif word == "{":
            stack.append(len(joints) - 1)
            i += 1
        elif word == "}":
            stack.pop()
            i += 1
        elif word == "CHANNELS":
            count = int(tokens[i + 1])
            channels += [(len(joints) - 1, name) for name in tokens[i + 2:i + 2 + count]]
            i += 2 + count
        else:  # OFFSET x y z
            i += 4
    frames = int(tokens[i + 2])
    values = [float(value) for value in tokens[i + 6:]]
    check(len(values) == frames * len(channels), "the hit's BVH has every frame's channels")
    result = {name: [] for name, _ in joints}
    for frame in range(frames):
        row = values[frame * len(channels):(frame + 1) * len(channels)]
        local = [Matrix.Identity(3) for _ in joints]
        for (joint, name), value in zip(channels, row):
            if name.endswith("rotation"):
                local[joint] = local[joint] @ Matrix.Rotation(math.radians(value), 3, name[0])
        world = []
        for index, (name, parent) in enumerate(joints):
            world.append(local[index] if parent is None else world[parent] @ local[index])
            result[name].append(world[index])
    return result


def largest_difference(armature, expected, frame_start, shift=0):
    """The largest angle, in degrees, between four joints' rotations at three frames of the
    imported action and the BVH's SHIFT frames later."""
    count = len(expected["Hips"])
    # Blender's importer reads BVH axes (-Z forward, Y up) into Blender's (Y forward, Z up).
    to_blender = axis_conversion(from_forward="-Z", from_up="Y")
    worst = 0.0
    for frame in (0, count // 2, count - 1 - shift):
        bpy.context.scene.frame_set(frame_start + frame)
        for joint in JOINTS:
            pose = armature.pose.bones[joint].matrix.to_3x3()
            actual = pose @ armature.data.bones[joint].matrix_local.to_3x3().inverted()
            want = to_blender @ expected[joint][frame + shift] @ to_blender.transposed()
            worst = max(worst, math.degrees((want.transposed() @ actual).to_quaternion().angle))
    return worst


def check_rotations(armature, bvh_text, frame_start):
    expected = bvh_global_rotations(bvh_text)
    worst = largest_difference(armature, expected, frame_start)
    check(worst < 0.5, f"{', '.join(JOINTS)} at 3 frames turn as the hit's BVH does "
                       f"(largest difference {worst:.4f} degrees)")
    # The comparison sees a wrong frame: the BVH's frames 12 later (0.1 s) differ.
    shifted = largest_difference(armature, expected, frame_start, shift=12)
    check(shifted > 2.0, f"against frames 12 later they differ ({shifted:.2f} degrees)")


def stick_figure(armature, color, radius=0.5):
    """A mesh of the armature's bones as posed now, a square rod a bone (bones do not render)."""
    vertices, faces = [], []
    for bone in armature.pose.bones:
        head, tail = armature.matrix_world @ bone.head, armature.matrix_world @ bone.tail
        along = tail - head
        if along.length < 1e-6:
            continue
        side = along.orthogonal().normalized() * radius
        up = along.cross(side).normalized() * radius
        base = len(vertices)
        for end in (head, tail):
            vertices += [end + side + up, end - side + up, end - side - up, end + side - up]
        faces += [(base + a, base + b, base + 4 + b, base + 4 + a)
                  for a, b in ((0, 1), (1, 2), (2, 3), (3, 0))]
        faces += [(base, base + 3, base + 2, base + 1), (base + 4, base + 5, base + 6, base + 7)]
    mesh = bpy.data.meshes.new(f"{armature.name} sticks")
    mesh.from_pydata(vertices, [], faces)
    sticks = bpy.data.objects.new(mesh.name, mesh)
    bpy.context.scene.collection.objects.link(sticks)
    sticks.color = color
    return sticks


def render(path, armatures):
    """The armatures as stick figures, from the front with an orthographic camera that frames
    them, rendered by the workbench engine to PATH."""
    scene = bpy.context.scene
    for obj in [obj for obj in scene.objects if obj.type in ("MESH", "LIGHT", "CAMERA")]:
        bpy.data.objects.remove(obj)  # the factory scene's cube, light and camera
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.color_type = "OBJECT"
    scene.render.resolution_x, scene.render.resolution_y = 480, 270
    scene.render.filepath = path
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.compression = 100  # small enough to commit (docs/)
    colors = ((0.25, 0.5, 0.9, 1.0), (0.95, 0.55, 0.2, 1.0))
    points = []
    for armature, color in zip(armatures, colors):
        stick_figure(armature, color)
        points += [armature.matrix_world @ bone.head for bone in armature.pose.bones]
    low = [min(point[axis] for point in points) for axis in range(3)]
    high = [max(point[axis] for point in points) for axis in range(3)]
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 1.3 * max(high[0] - low[0], (high[2] - low[2]) * 16 / 9)
    # From the front (-Y), looking along +Y.
    camera.location = ((low[0] + high[0]) / 2, low[1] - 10 * camera.data.ortho_scale,
                       (low[2] + high[2]) / 2)
    camera.rotation_euler = (math.radians(90), 0.0, 0.0)
    camera.data.clip_end = 100 * camera.data.ortho_scale
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(path)
    pixels = image.pixels[:]
    background = tuple(pixels[:3])
    figure = sum(1 for k in range(0, len(pixels), 4)
                 if max(abs(pixels[k + c] - background[c]) for c in range(3)) > 0.1)
    check(image.size[0] == 480 and figure > 0.02 * 480 * 270,
          f"the render {path} shows the figures ({figure} pixels not background)")


# -- Install from the zip and enable, as a user does.
bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
bpy.ops.preferences.addon_enable(module="motiondb_blender")
check(addon_utils.check("motiondb_blender")[1], "the add-on installs from the zip and is enabled")
import motiondb_blender  # noqa: E402  (importable once installed)
from motiondb_blender import bvh_io, operators  # noqa: E402

check(motiondb_blender.__file__.startswith(bpy.utils.user_resource("SCRIPTS")),
      "the enabled add-on is the one installed from the zip")
spaces = {bpy.types.MOTIONDB_PT_view3d.bl_space_type, bpy.types.MOTIONDB_PT_dopesheet.bl_space_type}
check(spaces == {"VIEW_3D", "DOPESHEET_EDITOR"} and
      bpy.types.MOTIONDB_PT_view3d.bl_region_type == "UI", "the panel is in both sidebars")
prefs = bpy.context.preferences.addons["motiondb_blender"].preferences
prefs.server_url = url
prefs.token_file = token_file
prefs.tls_ca = tls_ca
bpy.ops.motiondb.connect()
state = bpy.context.window_manager.motiondb
check([space.name for space in state.spaces] == ["body"], "Connect lists the server's space")

# -- Load a take and search with a range of it.
scene = bpy.context.scene
take = bvh_io.import_bvh(take_path, update_scene_fps=True, update_scene_duration=True)
scene.use_preview_range = True
scene.frame_preview_start, scene.frame_preview_end = 100, 300
scene.motiondb.mirror, scene.motiondb.max_results = True, 20
bpy.ops.motiondb.search()
mirrored = [hit for hit in state.hits if hit.mirrored]
check(mirrored and not state.hits[0].mirrored,
      f"with Mirror, {len(mirrored)} of {len(state.hits)} hits are the mirror's, hit 1 is not")
scene.motiondb.mirror, scene.motiondb.max_results = False, 5
bpy.ops.motiondb.search()
hits = list(state.hits)
check(1 <= len(hits) <= 5, f"the search found {len(hits)} hits (max 5)")
hit = hits[0]
# Blender's importer put the take's frame 0 at frame 1: frames 100-300 are clip frames 99-299.
overlap = min(hit.last_frame, 299) - max(hit.first_frame, 99)
check(hit.clip_id == 1 and overlap > 150 and hit.score < 0.05,
      f"hit 1 is the query's own range: clip {hit.clip_id} frames {hit.first_frame}-"
      f"{hit.last_frame}, score {hit.score:.4f}")
check(all(a.score <= b.score for a, b in zip(hits, hits[1:])), "the hits are ranked by score")

# -- Import hit 1 at frame 500 onto the take's armature (the same skeleton).
scene.frame_current = 500
state.hit_index = 0
bpy.ops.motiondb.import_hit()
armature = bpy.context.active_object
action = armature.animation_data.action
hit_bvh = api(f"/v1/clips/1/file?format=bvh&from={hit.first_frame}&to={hit.last_frame}").decode()
frames = hit.last_frame - hit.first_frame + 1
check(armature == take and action.name == f"01_01 {hit.first_frame}-{hit.last_frame}",
      f"hit 1 is a new action '{action.name}' on the take's armature")
check(tuple(action.frame_range) == (500, 500 + frames - 1) and
      len(action.fcurves.find('pose.bones["Hips"].location', index=0).keyframe_points) == frames,
      f"the action has the hit's {frames} frames from frame 500")
check_rotations(armature, hit_bvh, 500)

# -- The whole clip, with an armature of another skeleton active: a new armature.
scene.frame_set(500)
bpy.ops.object.armature_add()
other = bpy.context.active_object
bpy.ops.motiondb.import_hit(whole_clip=True)
clip_armature = bpy.context.active_object
check(clip_armature not in (other, take) and clip_armature.type == "ARMATURE" and
      clip_armature.animation_data.action.name == "01_01" and
      tuple(clip_armature.animation_data.action.frame_range) == (500, 500 + 2752 - 1),
      "the whole clip (2752 frames) comes in on a new armature when the skeletons differ")
bpy.data.objects.remove(other)

# -- Label the selected keys, frames 520-600 of hit 1 (clip frames first+20 to first+100), and
# find it (the preview range, still 100-300, is not the range).
bpy.context.view_layer.objects.active = take
scene.motiondb.range_source = "SELECTED_KEYS"
scene.motiondb.space = "body"
scene.motiondb.descriptor, scene.motiondb.value = "blender-kick", 0.75
for curve in action.fcurves:
    for point in curve.keyframe_points:
        point.select_control_point = False
message = operator_error(bpy.ops.motiondb.label)
check(f"no keyframe of action '{action.name}' is selected" in message,
      f"no keys selected: {message.strip()}")
for curve in action.fcurves:
    for point in curve.keyframe_points:
        point.select_control_point = 520 <= point.co.x <= 600
bpy.ops.motiondb.label()
found = json.loads(api("/v1/labels:find?descriptor=blender-kick"))["labels"]
check(len(found) == 1 and found[0]["clip_id"] == "1" and
      abs(found[0]["first_frame"] - (hit.first_frame + 20)) <= 1 and
      abs(found[0]["last_frame"] - (hit.first_frame + 100)) <= 1 and found[0]["value"] == 0.75,
      f"the label is found through the API on clip 1 frames {found[0]['first_frame']}-"
      f"{found[0]['last_frame']} (hit frames {hit.first_frame}+20 to +100)")

bpy.ops.motiondb.search()
check("blender-kick" in state.hits[0].labels,
      f"searching again, hit 1 shows the label: {state.hits[0].labels}")

# -- Propagate it and follow the job to its end, as the timer does.
bpy.ops.motiondb.propagate()
check(bpy.app.timers.is_registered(operators.follow_job), "the job is followed by a timer")
bpy.app.timers.unregister(operators.follow_job)  # -b runs no timers: follow it here
looks = 1
while operators.follow_job() is not None:
    looks += 1
    time.sleep(0.1)  # only to spare the server: the loop ends on the job's state
check(" succeeded: 1/1 labels searched" in state.job_status,
      f"the job's end is shown after {looks} looks: {state.job_status}")

# -- Ingest the active action (hit 1 as Blender holds it).
bpy.ops.motiondb.ingest_action()
clip_id = action[operators.CLIP_ID]
clip = json.loads(api(f"/v1/clips/{clip_id}"))
check(clip_id > 2 and clip["frame_count"] == frames and "blender" in clip["tags"],
      f"the action is ingested as clip {clip_id} ({clip['frame_count']} frames, tag blender)")
bpy.ops.motiondb.ingest_file(filepath=take_path)
taken = json.loads(api("/v1/clips?name_contains=take_01_01"))["clips"]
check(len(taken) == 1 and taken[0]["frame_count"] == 480,
      f"the take's file is ingested as clip {taken[0]['clip_id']} ('{taken[0]['name']}')")

# -- Errors are readable reports, not tracebacks.
prefs.token_file = ""
prefs.token = "not-the-token"
message = operator_error(bpy.ops.motiondb.search)
check("refused the token (401)" in message and "Traceback" not in message,
      f"a bad token: {message.strip()}")
prefs.token_file = token_file + ".missing"
message = operator_error(bpy.ops.motiondb.connect)
check(f"cannot read the token file {token_file}.missing" in message,
      f"a missing token file: {message.strip()}")
prefs.token_file, prefs.tls_ca = token_file, ""
message = operator_error(bpy.ops.motiondb.connect)
check("TLS: CERTIFICATE_VERIFY_FAILED" in message,
      f"without the CA, the server's certificate: {message.strip()}")
prefs.server_url = url.replace("https://", "http://")
message = operator_error(bpy.ops.motiondb.connect)
check(f"the connection to {prefs.server_url} failed" in message and
      "(is it an https:// server?)" in message, f"plain HTTP to the HTTPS port: {message.strip()}")
prefs.server_url = dead_url
message = operator_error(bpy.ops.motiondb.connect)
check(f"cannot reach the motiondb server at {dead_url}: Connection refused" in message,
      f"a dead server: {message.strip()}")
prefs.server_url = "127.0.0.1:8080"
message = operator_error(bpy.ops.motiondb.connect)
check("is not http://HOST:PORT" in message, f"a URL without its scheme: {message.strip()}")

clip_armature.location.x = 40.0
scene.frame_set(560)  # also moves the clip's armature to its new place
render(out_png, (take, clip_armature))
bpy.ops.preferences.addon_disable(module="motiondb_blender")
print("ADDON CHECKS PASSED")
