"""Exports lamp-shade.gltf with Blender's own glTF exporter: a trap of Blender's default export
(issue 57, docs/design.md §6.1 "Slow solves").

A floor lit by an emissive ceiling panel, and a table lamp: a closed cylinder (Blender's default
cylinder, capped) as its shade, white (base colour 1.0), with an emissive bulb inside. Blender
makes every material double-sided unless "Backface Culling" is ticked, so the shade's inside is a
closed cavity of reflectance 1 (clamped to 0.999): a mirror box around the bulb, which makes
rad-global's solve take thousands of sweeps. The export keeps Blender's defaults but for
"Cameras" (a camera to render from). --one-sided ticks Backface Culling on the shade's material,
the fix the warning suggests; --shade-colour sets its base colour.

usage: blender -b -P make_lamp_shade.py -- OUT.gltf [--one-sided] [--shade-colour 1.0]
"""
import math
import sys

import bpy

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if not args or args[0].startswith("-"):
    sys.exit("usage: blender -b -P make_lamp_shade.py -- OUT.gltf [--one-sided] "
             "[--shade-colour C]")
out = args[0]
one_sided = "--one-sided" in args
shade_colour = float(args[args.index("--shade-colour") + 1]) if "--shade-colour" in args else 1.0

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene


def material(name, colour, emission=0.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (colour, colour, colour, 1.0)
    if emission > 0.0:
        bsdf.inputs["Emission"].default_value = (1.0, 1.0, 1.0, 1.0)
        bsdf.inputs["Emission Strength"].default_value = emission
    return m


def add(obj, mat, name):
    obj.name = name
    obj.data.name = name
    obj.data.materials.append(mat)
    return obj


bpy.ops.mesh.primitive_plane_add(size=4.0)
add(bpy.context.object, material("Floor", 0.5), "Floor")
bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.0, 0.0, 2.5))
panel = add(bpy.context.object, material("Panel", 0.0, emission=5.0), "Panel")
panel.rotation_euler = (math.pi, 0.0, 0.0)  # facing down
shade_material = material("White", shade_colour)
shade_material.use_backface_culling = one_sided
bpy.ops.mesh.primitive_cylinder_add(vertices=12, radius=0.25, depth=0.3, location=(0.0, 0.0, 0.6))
add(bpy.context.object, shade_material, "Shade")
bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=1, radius=0.05, location=(0.0, 0.0, 0.6))
add(bpy.context.object, material("Bulb", 0.0, emission=20.0), "Bulb")
bpy.ops.object.camera_add(location=(2.6, -2.6, 1.8))
camera = bpy.context.object
camera.name = "Camera"
direction = -camera.location  # look at the origin's neighbourhood
camera.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
scene.camera = camera
scene.render.resolution_x, scene.render.resolution_y = 352, 240

bpy.ops.export_scene.gltf(filepath=out, export_format="GLTF_EMBEDDED", export_cameras=True)
