"""Run the Blender extension headless in ``bpy`` (Blender as a Python module): the test's
script, run by ``out/bpy-venv/bin/python`` (``make bpy-venv``).

``python check_extension.py EXAMPLE OUT [--python PY] [--render PNG]`` makes a mesh object of a
built-in example, registers the extension as Blender does, runs Preview and Export pattern
(into ``OUT/export``; with ``--python``, also in a subprocess of that Python into
``OUT/export-subprocess``), optionally renders the preview object with Cycles, and prints what
it made as JSON on its last line.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import bpy  # noqa: E402
import filletfold_blender  # noqa: E402


def mesh_object(name: str):
    from filletfold.mesh import example_mesh

    v, faces = example_mesh(name)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(v.tolist(), [], [f.tolist() for f in faces])
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def render(obj, path: Path) -> None:
    """The preview object, shaded, from the front (Cycles on the CPU: no display needed)."""
    from mathutils import Vector

    scene = bpy.context.scene
    for other in list(scene.objects):
        if other is not obj and other.type == "MESH":
            other.hide_render = True
    for material in obj.data.materials:  # the kinds' colours as the surface's colour
        material.use_nodes = True
        bsdf = material.node_tree.nodes.get("Principled BSDF")
        if bsdf is not None:
            bsdf.inputs["Base Color"].default_value = material.diffuse_color
    camera = scene.camera or bpy.data.objects.get("Camera")
    if camera is None:
        camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        scene.collection.objects.link(camera)
        scene.camera = camera
    centre = sum((obj.matrix_world @ Vector(c) for c in obj.bound_box), Vector()) / 8
    camera.location = centre + Vector((2.6, -3.4, 1.9))
    camera.rotation_euler = (centre - camera.location).to_track_quat("-Z", "Y").to_euler()
    light = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    light.rotation_euler = (0.7, 0.2, 0.6)
    light.data.energy = 3.0
    scene.collection.objects.link(light)
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.color = (0.9, 0.9, 0.9)
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 16
    scene.render.resolution_x, scene.render.resolution_y = 640, 480
    scene.render.film_transparent = False
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("example")
    parser.add_argument("out")
    parser.add_argument("--python", default="")
    parser.add_argument("--render", default="")
    args = parser.parse_args(argv)
    out = Path(args.out)
    filletfold_blender.register()
    obj = mesh_object(args.example)
    bpy.context.view_layer.objects.active = obj
    settings = bpy.context.scene.filletfold
    assert bpy.ops.filletfold.preview() == {"FINISHED"}, settings.message
    settings.radius = "12%"  # a change without live preview: the preview stays
    settings.live = True  # live: redrawn now, and on every change
    settings.radius = "10%"
    preview = bpy.data.objects[args.example + filletfold_blender.PREVIEW_SUFFIX]
    mesh = preview.data
    result = {
        "objects": sorted(o.name for o in bpy.data.objects if o.type == "MESH"),
        "faces": len(mesh.polygons),
        "vertices": len(mesh.vertices),
        "materials": [m.name for m in mesh.materials],
        "kinds": [a.value for a in mesh.attributes["filletfold_kind"].data],
        "patches": [a.value for a in mesh.attributes["filletfold_patch"].data],
        "status": list(preview["filletfold_status"]),
        "message": settings.message,
    }
    done = bpy.ops.filletfold.export_pattern(directory=str(out / "export"))
    result["export"] = sorted(p.name for p in (out / "export").iterdir()) if done else []
    if args.python:
        settings.python = args.python
        bpy.context.view_layer.objects.active = preview  # the panel works on its source
        assert bpy.ops.filletfold.preview() == {"FINISHED"}, settings.message
        result["subprocess_faces"] = len(preview.data.polygons)
        done = bpy.ops.filletfold.export_pattern(directory=str(out / "export-subprocess"))
        result["subprocess_export"] = sorted(p.name for p in (out / "export-subprocess").iterdir())
        settings.python = "/nonexistent/python"
        try:  # a failed operator raises in background mode, with its report
            bpy.ops.filletfold.preview()
        except RuntimeError as exc:
            result["bad_python"] = [str(exc), settings.message]
    obj_file = out / f"{args.example}.obj"  # the mesh as Blender holds it (float32), for the CLI
    vertices, faces = filletfold_blender.mesh_arrays(obj)
    filletfold_blender.engine.write_obj(obj_file, vertices, faces)
    result["obj"] = str(obj_file)
    if args.render:
        render(preview, Path(args.render))
    filletfold_blender.unregister()
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
