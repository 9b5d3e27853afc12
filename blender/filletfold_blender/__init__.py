"""filletfold in Blender (4.2+ extension): a panel on the selected mesh with the main
parameters, a live preview object of the folded design, and "Export pattern", which writes the
files ``filletfold round MESH -o FOLDER`` writes.

The panel is in the 3D view's sidebar (N), tab "filletfold". The preview is an object named
``<mesh>.filletfold`` at the mesh's place: one material per patch kind (cone, cylinder, fillet,
face, coloured as filletfold's pictures) and the face attributes ``filletfold_kind`` (the kind's
index in :data:`engine.KIND_ORDER`) and ``filletfold_patch`` (the patch's number); its custom
properties hold the summary and each vertex's status. The design runs in Blender's Python when
filletfold imports there, else in a subprocess of the panel's Python (:mod:`.engine`).
"""

from __future__ import annotations

import bpy
from bpy.props import BoolProperty, EnumProperty, IntProperty, PointerProperty, StringProperty

from . import engine

PREVIEW_SUFFIX = ".filletfold"
SHARP_ITEMS = [
    ("auto", "auto", "All cone-less vertices sharp (with material loss: all but boundary)"),
    ("none", "none", "Holes at cone-less vertices (the paper's construction)"),
    ("all", "all", "Every cone-less vertex kept sharp"),
    ("saddle,infeasible", "saddle, infeasible", "Saddles and infeasible vertices kept sharp"),
]


def _live(settings, context):
    """A parameter changed: redraw the preview when it is live (errors go to the panel)."""
    if settings.live:
        source = source_object(context)
        if source is not None:
            try:
                preview(context, source)
            except engine.EngineError as exc:
                settings.message = str(exc)


class FilletfoldSettings(bpy.types.PropertyGroup):
    radius: StringProperty(
        name="Radius", default="10%", update=_live,
        description="Rounding radius: a length, or N% of the mean edge length",
    )  # fmt: skip
    depth: StringProperty(
        name="Depth", default="30%", update=_live,
        description="Apex depth along the vertex normal: a length, or N% of the mean edge",
    )  # fmt: skip
    samples: IntProperty(
        name="Samples", default=24, min=3, max=256, update=_live,
        description="Most points per arc",
    )  # fmt: skip
    sharp: EnumProperty(
        name="Sharp", items=SHARP_ITEMS, default="auto", update=_live,
        description="Which vertices without a cone keep their corner",
    )  # fmt: skip
    live: BoolProperty(
        name="Live preview", default=False, update=_live,
        description="Redraw the preview on every change",
    )  # fmt: skip
    python: StringProperty(
        name="Python", default="", subtype="FILE_PATH",
        description="A Python that has filletfold (empty: Blender's own, when filletfold is "
        "installed there)",
    )  # fmt: skip
    folder: StringProperty(
        name="Folder", default="//filletfold", subtype="DIR_PATH",
        description="Where Export pattern writes the design's files",
    )  # fmt: skip
    message: StringProperty(name="Message", default="")


def options(settings) -> engine.Options:
    return engine.Options(
        radius=settings.radius.strip() or "10%",
        depth=settings.depth.strip() or "30%",
        samples=int(settings.samples),
        sharp=settings.sharp,
    )


def source_object(context):
    """The mesh the panel works on: the active object, or the mesh its preview was made of."""
    obj = context.active_object
    if obj is not None and obj.get("filletfold_source"):
        obj = bpy.data.objects.get(obj["filletfold_source"])
    if obj is None or obj.type != "MESH":
        return None
    return obj


def mesh_arrays(obj):
    """The object's mesh (modifiers applied), in its own coordinates: vertices and faces."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        vertices = [tuple(v.co) for v in mesh.vertices]
        faces = [list(p.vertices) for p in mesh.polygons]
    finally:
        evaluated.to_mesh_clear()
    return vertices, faces


def _materials() -> list:
    out = []
    for kind in engine.KIND_ORDER:
        name = f"filletfold {kind}"
        material = bpy.data.materials.get(name) or bpy.data.materials.new(name)
        material.diffuse_color = (*engine.PATCH_COLOR[kind], 1.0)
        out.append(material)
    return out


def preview(context, source):
    """Make (or remake) the preview object of ``source`` from its design; returns it."""
    settings = context.scene.filletfold
    vertices, faces = mesh_arrays(source)
    result = engine.folded(
        vertices, faces, options(settings), settings.python.strip(), name=source.name
    )
    name = source.name + PREVIEW_SUFFIX
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in result["vertices"]], [], result["faces"])
    for material in _materials():
        mesh.materials.append(material)
    kinds = [p.split()[0] for p in result["patches"]]
    numbers = {p: k for k, p in enumerate(dict.fromkeys(result["patches"]))}
    kind_index = [engine.KIND_ORDER.index(k) if k in engine.KIND_ORDER else 0 for k in kinds]
    mesh.polygons.foreach_set("material_index", kind_index)
    mesh.attributes.new("filletfold_kind", "INT", "FACE").data.foreach_set("value", kind_index)
    patch = [numbers[p] for p in result["patches"]]
    mesh.attributes.new("filletfold_patch", "INT", "FACE").data.foreach_set("value", patch)
    mesh.update()
    obj = bpy.data.objects.get(name)
    if obj is None:
        obj = bpy.data.objects.new(name, mesh)
        for collection in source.users_collection or [context.scene.collection]:
            collection.objects.link(obj)
    else:
        old = obj.data
        obj.data = mesh
        if old.users == 0:
            bpy.data.meshes.remove(old)
    obj.matrix_world = source.matrix_world.copy()
    obj["filletfold_source"] = source.name
    obj["filletfold_summary"] = result["summary"]
    obj["filletfold_status"] = list(result["status"])
    settings.message = result["summary"].splitlines()[-1] if result["summary"] else ""
    return obj


class FILLETFOLD_OT_preview(bpy.types.Operator):
    """Round the selected mesh and show the folded design beside it"""

    bl_idname = "filletfold.preview"
    bl_label = "Preview"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender reads it from the class)

    @classmethod
    def poll(cls, context):
        return source_object(context) is not None

    def execute(self, context):
        try:
            preview(context, source_object(context))
        except engine.EngineError as exc:
            context.scene.filletfold.message = str(exc)
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        return {"FINISHED"}


class FILLETFOLD_OT_export(bpy.types.Operator):
    """Write the design's files (design.fold, report.json, folded.obj, pattern.svg), as
    filletfold round does"""

    bl_idname = "filletfold.export_pattern"
    bl_label = "Export pattern"

    directory: StringProperty(name="Folder", subtype="DIR_PATH", default="")

    @classmethod
    def poll(cls, context):
        return source_object(context) is not None

    def execute(self, context):
        settings = context.scene.filletfold
        source = source_object(context)
        folder = bpy.path.abspath(self.directory or settings.folder)
        vertices, faces = mesh_arrays(source)
        try:
            written = engine.export(
                vertices, faces, options(settings), folder, settings.python.strip(),
                name=source.name,
            )  # fmt: skip
        except engine.EngineError as exc:
            settings.message = str(exc)
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        settings.message = f"wrote {len(written)} files to {folder}"
        self.report({"INFO"}, settings.message)
        return {"FINISHED"}


class FILLETFOLD_PT_panel(bpy.types.Panel):
    bl_label = "filletfold"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "filletfold"

    def draw(self, context):
        layout, settings = self.layout, context.scene.filletfold
        source = source_object(context)
        layout.label(text=f"Mesh: {source.name}" if source else "Select a mesh")
        for name in ("radius", "depth", "samples", "sharp", "live"):
            layout.prop(settings, name)
        layout.operator(FILLETFOLD_OT_preview.bl_idname)
        layout.prop(settings, "folder")
        layout.operator(FILLETFOLD_OT_export.bl_idname)
        layout.prop(settings, "python")
        if settings.message:
            layout.label(text=settings.message)


CLASSES = (FilletfoldSettings, FILLETFOLD_OT_preview, FILLETFOLD_OT_export, FILLETFOLD_PT_panel)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.filletfold = PointerProperty(type=FilletfoldSettings)


def unregister():
    del bpy.types.Scene.filletfold
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
