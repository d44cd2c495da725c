"""The add-on's operators: connect, search, import a hit or its clip, label, propagate, ingest.

Each reports a failure in Blender's report area (self.report) and cancels; none lets an
exception through to a traceback.
"""
import os
import tempfile

import bpy
from bpy.props import BoolProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

from . import api, bvh_io

# Custom properties on an action that came from (or went to) the library: which clip, the
# second of the clip its first frame shows, and the Blender frame that first frame is at.
CLIP_ID = "motiondb_clip_id"
CLIP_START_S = "motiondb_start_s"
FRAME_START = "motiondb_frame_start"


class UserError(Exception):
    """Something the user can fix in Blender (no armature, no range): its message is reported."""


def client(context):
    """A client from the add-on's preferences."""
    prefs = context.preferences.addons[__package__].preferences
    token = prefs.token.strip() or None
    if prefs.token_file.strip():
        token = api.read_token_file(bpy.path.abspath(prefs.token_file.strip()))
    return api.Client(prefs.server_url, token=token,
                      tls_ca=bpy.path.abspath(prefs.tls_ca) if prefs.tls_ca.strip() else None)


def tags(text):
    """The tags of a comma-separated field."""
    return [tag.strip() for tag in text.split(",") if tag.strip()]


def active_armature(context):
    obj = context.active_object
    if obj is None or obj.type != "ARMATURE":
        raise UserError("select an armature (the active object is not one)")
    return obj


def active_action(context):
    obj = active_armature(context)
    action = obj.animation_data.action if obj.animation_data else None
    if action is None:
        raise UserError(f"armature '{obj.name}' has no action")
    return obj, action


def scene_fps(scene):
    return scene.render.fps / scene.render.fps_base


def query_range(context, action):
    """The frames a search or a label covers: the preview range or the selected keyframes'."""
    scene = context.scene
    if context.scene.motiondb.range_source == "PREVIEW":
        if not scene.use_preview_range:
            raise UserError("turn on the timeline's preview range, or search with the selected "
                            "keyframes")
        return scene.frame_preview_start, scene.frame_preview_end
    frames = [point.co.x for curve in action.fcurves for point in curve.keyframe_points
              if point.select_control_point]
    if not frames:
        raise UserError(f"no keyframe of action '{action.name}' is selected")
    return round(min(frames)), round(max(frames))


class MotiondbOperator(bpy.types.Operator):
    """What every operator shares: run() does the work, errors become reports."""
    bl_options = {"REGISTER"}

    def execute(self, context):
        try:
            return self.run(context)
        except (api.ApiError, UserError, ValueError, OSError, RuntimeError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        except KeyError as error:
            self.report({"ERROR"}, f"the server's answer has no {error}: is it motiondb?")
            return {"CANCELLED"}


class MOTIONDB_OT_connect(MotiondbOperator):
    bl_idname = "motiondb.connect"
    bl_label = "Connect"
    bl_description = "Ask the server for its spaces (and whether the token is accepted)"

    def run(self, context):
        server = client(context)
        info = server.info()
        state = context.window_manager.motiondb
        state.spaces.clear()
        for space in server.spaces():
            state.spaces.add().name = space["name"]
        settings = context.scene.motiondb
        if not settings.space and len(state.spaces):
            settings.space = state.spaces[0].name
        clips = info.get("counts", {}).get("clips", "0")
        self.report({"INFO"}, f"motiondb {info.get('version', '?')} at {server.url}: {clips} "
                              f"clips, {len(state.spaces)} spaces")
        return {"FINISHED"}


class MOTIONDB_OT_search(MotiondbOperator):
    bl_idname = "motiondb.search"
    bl_label = "Search"
    bl_description = "Search the library with the active action over the chosen range"

    def run(self, context):
        settings = context.scene.motiondb
        if not settings.space:
            raise UserError("choose a space (Connect lists the server's)")
        armature, action = active_action(context)
        first, last = query_range(context, action)
        text = bvh_io.write_bvh(context.scene, armature, first, last)
        server = client(context)
        results = server.search(settings.space, text, settings.max_results,
                                mirror=settings.mirror, tags=tags(settings.tags))
        labels = {}  # each hit clip's labels, fetched once
        hits = context.window_manager.motiondb.hits
        hits.clear()
        for result in results:
            clip_id = int(result["clip_id"])
            if clip_id not in labels:
                labels[clip_id] = server.clip_labels(clip_id)
            hit = hits.add()
            hit.clip_id = clip_id
            hit.clip_name = result.get("clip_name", "")
            hit.first_frame = result.get("start_frame", 0)
            hit.last_frame = result.get("end_frame", 0)
            hit.start_s = result.get("start_s", 0.0)
            hit.score = result.get("score", 0.0)
            hit.mirrored = result.get("mirrored", False)
            hit.labels = ", ".join(sorted({
                label["descriptor_name"] for label in labels[clip_id]
                if label.get("first_frame", 0) <= hit.last_frame
                and label.get("last_frame", 0) >= hit.first_frame}))
        context.window_manager.motiondb.hit_index = 0
        self.report({"INFO"}, f"{len(hits)} hits for frames {first}-{last} in space "
                              f"'{settings.space}'")
        return {"FINISHED"}


def import_from_library(context, server, clip_id, first=None, last=None, start_s=0.0):
    """The clip (or its frames first..last) as an action at the current frame: on the active
    armature when its skeleton is the clip's, else on a new armature. Returns (armature, action,
    whether a new armature was made)."""
    text = server.export_bvh(clip_id, first, last)
    scene = context.scene
    target = context.active_object if context.active_object and \
        context.active_object.type == "ARMATURE" else None
    # Blender's importer places the first frame at frame 1 at the earliest.
    frame = max(1, scene.frame_current)
    # Keep the clip's timing when its rate is not the scene's.
    use_fps_scale = abs(1.0 / bvh_io.frame_time(text) - scene_fps(scene)) > 1e-3
    name = server.clip(clip_id).get("name", f"clip {clip_id}")
    with tempfile.TemporaryDirectory(prefix="motiondb_") as folder:
        path = os.path.join(folder, f"{name}.bvh")
        with open(path, "w", encoding="utf-8") as file:
            file.write(text)
        imported = bvh_io.import_bvh(path, frame_start=frame, use_fps_scale=use_fps_scale,
                                     update_scene_fps=False, update_scene_duration=False)
    action = imported.animation_data.action
    action.name = name if first is None else f"{name} {first}-{last}"
    action[CLIP_ID] = int(clip_id)
    action[CLIP_START_S] = float(start_s)
    action[FRAME_START] = frame
    if target is None or not same_skeleton(target, imported):
        return imported, action, True
    armature_data = imported.data
    bpy.data.objects.remove(imported)
    bpy.data.armatures.remove(armature_data)
    if target.animation_data is None:
        target.animation_data_create()
    target.animation_data.action = action
    context.view_layer.objects.active = target
    target.select_set(True)
    return target, action, False


def same_skeleton(armature, other):
    """The same bones by name, each at the same rest orientation (an action of one then poses
    the other alike)."""
    bones, other_bones = armature.data.bones, other.data.bones
    if {bone.name for bone in bones} != {bone.name for bone in other_bones}:
        return False
    for bone in bones:
        difference = bone.matrix_local.to_3x3() - other_bones[bone.name].matrix_local.to_3x3()
        if max(abs(value) for row in difference for value in row) > 1e-4:
            return False
    return True


class MOTIONDB_OT_import_hit(MotiondbOperator):
    bl_idname = "motiondb.import_hit"
    bl_label = "Import hit"
    bl_description = ("Import the selected hit at the current frame: a new action on the active "
                      "armature when its skeleton matches, else a new armature")
    bl_options = {"REGISTER", "UNDO"}
    whole_clip: BoolProperty(name="Whole clip", default=False)

    def run(self, context):
        state = context.window_manager.motiondb
        if not 0 <= state.hit_index < len(state.hits):
            raise UserError("no hit selected: search first")
        hit = state.hits[state.hit_index]
        server = client(context)
        if self.whole_clip:
            armature, action, new = import_from_library(context, server, hit.clip_id)
        else:
            armature, action, new = import_from_library(context, server, hit.clip_id,
                                                        hit.first_frame, hit.last_frame,
                                                        hit.start_s)
        where = f"new armature '{armature.name}'" if new else f"armature '{armature.name}'"
        self.report({"INFO"}, f"imported '{action.name}' onto {where} at frame "
                              f"{action[FRAME_START]}")
        if hit.mirrored:  # the server exports a clip as stored; its mirror image is not a file
            self.report({"WARNING"}, "this hit matched the query's mirror image: it is "
                                     "imported as stored, not mirrored")
        return {"FINISHED"}


def action_seconds(context, action, first, last):
    """Seconds of the action's library clip that Blender frames first..last show."""
    if CLIP_ID not in action:
        raise UserError(f"action '{action.name}' is not from the library: import a hit or a "
                        "clip, or ingest the action first")
    fps = scene_fps(context.scene)
    offset = action[CLIP_START_S] - action[FRAME_START] / fps
    return int(action[CLIP_ID]), offset + first / fps, offset + last / fps


class MOTIONDB_OT_label(MotiondbOperator):
    bl_idname = "motiondb.label"
    bl_label = "Label range"
    bl_description = ("Label the chosen range of the active action's library clip with the "
                      "descriptor and value")

    def run(self, context):
        settings = context.scene.motiondb
        if not settings.descriptor.strip():
            raise UserError("type a descriptor to label with")
        _, action = active_action(context)
        first, last = query_range(context, action)
        clip_id, start_s, end_s = action_seconds(context, action, first, last)
        labels = client(context).add_label(clip_id, start_s, end_s, settings.descriptor.strip(),
                                           settings.value)
        if not labels:
            raise UserError("the server skipped the label (its range is outside the clip)")
        label = labels[0]
        self.report({"INFO"}, f"labelled clip {clip_id} frames {label.get('first_frame', 0)}-"
                              f"{label.get('last_frame', 0)} '{label.get('descriptor_name')}' "
                              f"{label.get('value', 0.0):g}")
        return {"FINISHED"}


def follow_job():
    """One look at the job being followed: its progress in the status bar and the panel. The
    seconds until the next look, or None when it has ended (a bpy.app.timers function)."""
    state = bpy.context.window_manager.motiondb
    try:
        job = client(bpy.context).job(state.job_id)
    except (api.ApiError, OSError) as error:
        state.job_status = f"{state.job_id}: {error}"
        _status_bar(None)
        return None
    done, total = int(job.get("done", 0)), int(job.get("total", 0))
    status = job.get("state", "").replace("JOB_STATE_", "").lower()
    state.job_status = f"{state.job_id} {status}: {done}/{total} labels searched, " \
                       f"{job.get('labels_written', '0')} written"
    if job.get("error"):
        state.job_status += f" ({job['error']})"
    running = status in ("queued", "running")
    _status_bar(f"motiondb {state.job_status}" if running else None)
    return 1.0 if running else None


def _status_bar(text):
    for window in bpy.context.window_manager.windows:
        window.workspace.status_text_set(text)


class MOTIONDB_OT_propagate(MotiondbOperator):
    bl_idname = "motiondb.propagate"
    bl_label = "Propagate"
    bl_description = ("Start a job propagating the descriptor's labels through the space, and "
                      "follow it in the status bar")

    def run(self, context):
        settings = context.scene.motiondb
        if not settings.space or not settings.descriptor.strip():
            raise UserError("choose a space and type the descriptor to propagate")
        job = client(context).start_propagation(settings.space, [settings.descriptor.strip()])
        state = context.window_manager.motiondb
        state.job_id = job["job_id"]
        state.job_status = f"{state.job_id} started"
        if not bpy.app.timers.is_registered(follow_job):
            bpy.app.timers.register(follow_job, first_interval=0.5)
        self.report({"INFO"}, f"propagation {state.job_id} started")
        return {"FINISHED"}


def ingest_result(answer):
    clip = answer.get("clip", {})
    result = answer.get("result", "").replace("INGEST_RESULT_", "").lower()
    return int(clip.get("clip_id", 0)), f"clip {clip.get('clip_id')} '{clip.get('name')}' " \
                                        f"({clip.get('frame_count')} frames): {result}"


class MOTIONDB_OT_ingest_action(MotiondbOperator):
    bl_idname = "motiondb.ingest_action"
    bl_label = "Ingest action"
    bl_description = "Add the active action, over its frame range, to the library"

    def run(self, context):
        armature, action = active_action(context)
        first, last = (round(frame) for frame in action.frame_range)
        text = bvh_io.write_bvh(context.scene, armature, first, last)
        clip_id, said = ingest_result(client(context).ingest(
            f"{action.name}.bvh", text, tags(context.scene.motiondb.ingest_tags)))
        action[CLIP_ID] = clip_id
        action[CLIP_START_S] = 0.0
        action[FRAME_START] = first
        self.report({"INFO"}, f"ingested {said}")
        return {"FINISHED"}


class MOTIONDB_OT_ingest_file(MotiondbOperator, ImportHelper):
    bl_idname = "motiondb.ingest_file"
    bl_label = "Ingest file"
    bl_description = "Add a BVH, FBX or glTF file to the library"
    filter_glob: StringProperty(default="*.bvh;*.fbx;*.glb;*.gltf", options={"HIDDEN"})

    def run(self, context):
        with open(self.filepath, "rb") as file:
            data = file.read()
        _, said = ingest_result(client(context).ingest(
            os.path.basename(self.filepath), data, tags(context.scene.motiondb.ingest_tags)))
        self.report({"INFO"}, f"ingested {said}")
        return {"FINISHED"}


classes = (MOTIONDB_OT_connect, MOTIONDB_OT_search, MOTIONDB_OT_import_hit, MOTIONDB_OT_label,
           MOTIONDB_OT_propagate, MOTIONDB_OT_ingest_action, MOTIONDB_OT_ingest_file)
