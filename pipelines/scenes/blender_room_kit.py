"""Blender helpers of the lamp-scene generators (make_blender_lamp_room.py, make_blender_lamp_study.py),
run inside Blender: an empty 24-fps scene at the pipeline's 352x240, diffuse box furniture,
punctual lamps, a camera and Blender's own glTF export."""
import math

import bpy

_materials = {}


def new_scene(last_frame):
    """Blender's factory settings, emptied; frames 0..last_frame at 24 fps. The exporter writes the
    camera's aspectRatio from the render size: the pipeline's 352x240."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    _materials.clear()
    scene = bpy.context.scene
    scene.render.fps = 24
    scene.frame_start, scene.frame_end = 0, last_frame
    scene.render.resolution_x, scene.render.resolution_y = 352, 240
    return scene


def material(name, rgb):
    """A Principled BSDF of roughness 1 and specular 0 whose base colour is the reflectance the
    toolchain reads; one per name."""
    if name not in _materials:
        m = bpy.data.materials.new(name)
        m.use_nodes = True
        bsdf = m.node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Base Color"].default_value = (*rgb, 1.0)
        bsdf.inputs["Roughness"].default_value = 1.0
        bsdf.inputs["Specular"].default_value = 0.0
        _materials[name] = m
    return _materials[name]


def box(name, centre, size, mat):
    """An axis-aligned box (Blender Z-up), size in metres, mat a (name, rgb) pair."""
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=centre)
    o = bpy.context.active_object
    o.name = name
    o.scale = size
    bpy.ops.object.transform_apply(location=False, rotation=False, scale=True)
    o.data.materials.append(material(*mat))
    return o


def lamp(name, kind, energy, location, rotation=(0.0, 0.0, 0.0), colour=None):
    """A punctual lamp (radius 0, or a sun's angle 0) of Blender's energy; returns its data."""
    data = bpy.data.lights.new(name, kind)
    data.energy = energy
    if colour is not None:
        data.color = colour
    if kind == "SUN":
        data.angle = 0.0
    else:
        data.shadow_soft_size = 0.0
    o = bpy.data.objects.new(name, data)
    o.location = location
    o.rotation_euler = rotation
    bpy.context.scene.collection.objects.link(o)
    return data


def camera(angle_y_degrees, location, rotation_degrees):
    """The scene's camera, its vertical field of view fitted to the sensor's height."""
    cam = bpy.data.cameras.new("camera")
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = math.radians(angle_y_degrees)
    cam_obj = bpy.data.objects.new("camera", cam)
    cam_obj.location = location
    cam_obj.rotation_euler = tuple(math.radians(a) for a in rotation_degrees)
    bpy.context.scene.collection.objects.link(cam_obj)
    bpy.context.scene.camera = cam_obj


def export(out):
    """Blender's glTF exporter at its defaults but for cameras and lights, one embedded file."""
    bpy.ops.export_scene.gltf(filepath=out, export_format="GLTF_EMBEDDED", export_cameras=True,
                              export_lights=True)
