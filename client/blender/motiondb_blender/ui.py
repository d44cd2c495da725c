"""The add-on's settings and its sidebar panel in the 3-D viewport and the dope sheet.

Connection settings live in the add-on's preferences (Blender's user preferences, never the
.blend file); search options on the scene; hits and the followed job on the window manager, which
Blender does not save with the file.
"""
import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty,
                       IntProperty, PointerProperty, StringProperty)


class MotiondbPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    server_url: StringProperty(
        name="Server URL", default="http://127.0.0.1:8080",
        description="The server's HTTP face: http://HOST:PORT, or https:// when it serves TLS")
    token: StringProperty(
        name="Token", subtype="PASSWORD",
        description="Bearer token, when the server has --auth-token-file")
    token_file: StringProperty(
        name="Token file", subtype="FILE_PATH",
        description="A file holding the token (used instead of the typed token)")
    tls_ca: StringProperty(
        name="TLS CA", subtype="FILE_PATH",
        description="CA certificate (PEM) to trust for https://; empty: the system's")

    def draw(self, context):
        layout = self.layout
        for name in ("server_url", "token", "token_file", "tls_ca"):
            layout.prop(self, name)


class MotiondbHit(bpy.types.PropertyGroup):
    clip_id: IntProperty()
    clip_name: StringProperty()
    first_frame: IntProperty()  # at the clip's own rate, inclusive
    last_frame: IntProperty()
    start_s: FloatProperty()
    score: FloatProperty()
    mirrored: BoolProperty()
    labels: StringProperty()


class MotiondbSpaceName(bpy.types.PropertyGroup):
    pass  # its name is the space's


class MotiondbState(bpy.types.PropertyGroup):
    """What one session holds: the server's spaces, the hits, the followed job."""
    spaces: CollectionProperty(type=MotiondbSpaceName)
    hits: CollectionProperty(type=MotiondbHit)
    hit_index: IntProperty(name="Hit")
    job_id: StringProperty()
    job_status: StringProperty()


class MotiondbSettings(bpy.types.PropertyGroup):
    space: StringProperty(name="Space", description="The space to search and propagate in")
    range_source: EnumProperty(
        name="Range", default="PREVIEW",
        items=[("PREVIEW", "Preview range", "The timeline's preview range"),
               ("SELECTED_KEYS", "Selected keys", "From the first to the last selected keyframe")])
    max_results: IntProperty(name="Max results", default=20, min=1, max=1000)
    mirror: BoolProperty(name="Mirror", description="Also search the query's left/right mirror")
    tags: StringProperty(name="Tags", description="Only clips with one of these tags (commas)")
    descriptor: StringProperty(name="Descriptor", description="The label's descriptor")
    value: FloatProperty(name="Value", default=1.0, min=0.0, max=1.0)
    ingest_tags: StringProperty(name="Ingest tags", default="blender",
                                description="Tags of clips ingested from Blender (commas)")


class MOTIONDB_UL_hits(bpy.types.UIList):
    def draw_item(self, context, layout, data, hit, icon, active_data, active_property, index):
        row = layout.row(align=True)
        row.label(text=f"{index + 1}. {hit.clip_name}{' (mirror)' if hit.mirrored else ''}")
        row.label(text=f"{hit.first_frame}-{hit.last_frame}")
        row.label(text=f"{hit.score:.3f}")
        if hit.labels:
            row.label(text=hit.labels, icon="BOOKMARKS")


class MotiondbPanel:
    bl_region_type = "UI"
    bl_category = "motiondb"
    bl_label = "motiondb"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.motiondb
        state = context.window_manager.motiondb
        prefs = context.preferences.addons[__package__].preferences

        box = layout.box()
        row = box.row()
        row.label(text=prefs.server_url, icon="URL")
        row.operator("motiondb.connect", text="", icon="FILE_REFRESH")

        box = layout.box()
        box.prop_search(settings, "space", state, "spaces")
        box.prop(settings, "range_source")
        row = box.row()
        row.prop(settings, "max_results")
        row.prop(settings, "mirror")
        box.prop(settings, "tags")
        box.operator("motiondb.search", icon="VIEWZOOM")

        layout.template_list("MOTIONDB_UL_hits", "", state, "hits", state, "hit_index", rows=4)
        row = layout.row(align=True)
        row.operator("motiondb.import_hit", icon="IMPORT").whole_clip = False
        row.operator("motiondb.import_hit", text="Whole clip").whole_clip = True

        box = layout.box()
        row = box.row()
        row.prop(settings, "descriptor")
        row.prop(settings, "value", slider=True)
        row = box.row(align=True)
        row.operator("motiondb.label", icon="BOOKMARKS")
        row.operator("motiondb.propagate", icon="SHADERFX")
        if state.job_status:
            box.label(text=state.job_status)

        box = layout.box()
        box.prop(settings, "ingest_tags")
        row = box.row(align=True)
        row.operator("motiondb.ingest_action", icon="ACTION")
        row.operator("motiondb.ingest_file", icon="FILEBROWSER")


class MOTIONDB_PT_view3d(MotiondbPanel, bpy.types.Panel):
    bl_space_type = "VIEW_3D"


class MOTIONDB_PT_dopesheet(MotiondbPanel, bpy.types.Panel):
    bl_space_type = "DOPESHEET_EDITOR"


classes = (MotiondbPreferences, MotiondbHit, MotiondbSpaceName, MotiondbState, MotiondbSettings,
           MOTIONDB_UL_hits, MOTIONDB_PT_view3d, MOTIONDB_PT_dopesheet)


def register_properties():
    bpy.types.Scene.motiondb = PointerProperty(type=MotiondbSettings)
    bpy.types.WindowManager.motiondb = PointerProperty(type=MotiondbState)


def unregister_properties():
    del bpy.types.WindowManager.motiondb
    del bpy.types.Scene.motiondb
