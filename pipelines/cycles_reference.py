#!/usr/bin/env python3
"""Cycles references of a glTF scene: an independent renderer's frames for rad-diff
(docs/design.md §6.6, §10.2; issue 56).

Blender's glTF importer reads the scene; this script then makes Blender render it under this
project's scene model (docs/design.md §4) rather than Blender's defaults, and writes linear EXR
frames DIR/NNNN.exr like rad-reference's (RGB float, row 0 = top), which rad-diff reads:

  materials  the importer's Principled BSDF is replaced by a Lambertian Diffuse BSDF (Oren-Nayar
             roughness 0) of the same base colour (factor x texture, as the importer wired it;
             a constant clamped to 0.999 like the reader's) plus an Emission of the importer's
             colour and strength. The importer maps emissiveFactor x
             KHR_materials_emissive_strength to Emission x Strength, and a Cycles surface of
             strength S and colour C has exitant radiance C S: our $L_e$. The Principled BSDF
             itself is not Lambertian (Disney diffuse's retro-reflection, a specular layer).
  sides      a material that is not doubleSided is one-sided by winding: seen from behind, a
             camera ray passes through it (glTF culls back faces, and so do rad-compose's item
             buffer and rad-reference) and any other ray is absorbed (black, no emission).
             Cycles alone would shade and light both sides.
  camera     the importer sets yfov as the vertical angle with a vertical sensor fit, which is
             our projection when the camera has no aspectRatio or the image's (another
             aspectRatio stretches our frame, which Blender cannot do: refused). Pixel (c, r)'s
             centre is (c + 0.5, r + 0.5) in both.
  animation  Blender frame = glTF time x fps (the importer's rule, with render.fps = --fps);
             rotations are slerped between keys as glTF prescribes (the importer's f-curves
             interpolate quaternion components linearly). CUBICSPLINE samplers are refused:
             the importer drops their tangents.
  film       Cycles on the CPU, --spp samples with --seed, no adaptive sampling, no denoiser,
             no clamping, light threshold 0, --max-bounces of every kind, the pixel filter
             --pixel-filter of --filter-width pixels (by default blackman-harris 1.5, Cycles' own
             default), view transform Standard, exposure 0, film not transparent, a black world.
  filter     Blender gives Cycles a box filter 1 px wide whatever its width says (its
             sync.cpp: `filter_type == FILTER_BOX ? 1.0f : filter_width`), so a "box 0.01"
             render is an area average over each pixel, not the pixel centre: --pixel-filter
             box takes width 1 only. --pixel-filter none (Cycles' blackman-harris 0.01: every
             sample within 0.01 px of the centre) samples as rad-compose and rad-reference
             --pixel-filter none do; --pixel-centres is its older name, as theirs.

usage: cycles_reference.py SCENE -o DIR [--frames A-B|A-BxS|A] [--fps F] [--size WxH]
                           [--camera NAME] [--spp N] [--seed S]
                           [--pixel-filter none|box|gaussian|blackman-harris]
                           [--filter-width PX]
                           [--max-bounces N] [--threads N]
                           [--blender PATH] [--bin DIR]

Without --frames, the scene's animation as the stages cover it (rad-inspect --default-frames
from --bin). Run with python3: it starts `blender -b --factory-startup --python THIS -- ARGS`,
and the same file does the rendering inside Blender. Exit status: 0 ok, 1 bad input (scene,
camera, animation), 2 usage, 4 Blender missing or failed.
"""
import argparse
import json
import os
import shlex
import shutil
import struct
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
TOOL = "cycles_reference.py"
FILTERS = {"box": "BOX", "gaussian": "GAUSSIAN", "blackman-harris": "BLACKMAN_HARRIS"}


class InputError(Exception):
    """Bad scene, camera or animation: exit 1 with `cycles_reference.py: path: what`."""


def parse_args(argv):
    p = argparse.ArgumentParser(prog=TOOL, description=__doc__.split("\n\n")[0])
    p.add_argument("scene", help="glTF 2.0 scene (.gltf or .glb)")
    p.add_argument("-o", "--output", required=True, help="folder for NNNN.exr")
    p.add_argument("--frames", help="A-B, A-BxSTEP or A (default: the scene's animation)")
    p.add_argument("--fps", type=int, default=24, help="frames per second (an integer)")
    p.add_argument("--size", default="352x240", help="WxH")
    p.add_argument("--camera", default="", help="camera node (or camera) name; default the first")
    p.add_argument("--spp", type=int, default=1024, help="samples per pixel")
    p.add_argument("--seed", type=int, default=0, help="Cycles' seed")
    p.add_argument("--pixel-filter", choices=["none"] + sorted(FILTERS),
                   default="blackman-harris",
                   help="pixel filter (default blackman-harris, Cycles' default); none: every "
                   "sample within 0.01 px of the pixel centre")
    p.add_argument("--filter-width", type=float, default=1.5,
                   help="filter width, pixels (default 1.5; box: 1 only)")
    p.add_argument("--pixel-centres", action="store_true",
                   help="older name of --pixel-filter none")
    p.add_argument("--max-bounces", type=int, default=64, help="bounces of every kind")
    p.add_argument("--threads", type=int, default=0, help="render threads; 0: all cores")
    p.add_argument("--blender", default="blender", help="the blender executable")
    p.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"),
                   help="the tools (rad-inspect, for the default frames)")
    a = p.parse_args(argv)
    try:
        w, h = (int(v) for v in a.size.lower().split("x"))
        if w < 1 or h < 1:
            raise ValueError
    except ValueError:
        p.error("--size %s; expected WxH, both positive" % a.size)
    a.width, a.height = w, h
    if a.spp < 1 or a.fps < 1 or a.max_bounces < 0 or a.threads < 0:
        p.error("--spp and --fps must be >= 1, --max-bounces and --threads >= 0")
    if a.pixel_centres:
        if any(x.startswith("--pixel-filter") for x in argv):
            p.error("--pixel-centres is --pixel-filter none; give one of them")
        a.pixel_filter = "none"
    if a.pixel_filter == "none":  # Cycles' narrowest filter: samples within 0.01 px
        a.filter, a.filter_width = "blackman-harris", 0.01
    else:
        a.filter = a.pixel_filter
    if not 0.01 <= a.filter_width <= 10.0:
        p.error("--filter-width %g; expected in [0.01, 10] (Cycles' range)" % a.filter_width)
    if a.filter == "box" and a.filter_width != 1.0:
        p.error("--pixel-filter box --filter-width %g: Blender renders a box filter 1 px "
                "wide whatever its width; for pixel centres use --pixel-filter none" %
                a.filter_width)
    return a


def frame_list(text):
    """oiiotool's frame ranges: A, A-B, A-BxS."""
    step = 1
    if "x" in text:
        text, s = text.split("x", 1)
        step = int(s)
    first, _, last = text.partition("-")
    first = int(first)
    last = int(last) if last else first
    if step < 1 or last < first or first < 0:
        raise ValueError(text)
    return list(range(first, last + 1, step))


# --- outside Blender: start it


def default_frames(a):
    tool = os.path.join(a.bin, "rad-inspect")
    r = subprocess.run([tool, "--default-frames", a.scene, "--fps", str(a.fps)],
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise InputError(r.stderr.strip() or "rad-inspect --default-frames failed")
    return r.stdout.strip()


def blender_environment(blender):
    """Debian's blender embeds the system's libpython, whose modules (numpy, which the glTF
    importer needs) are under /usr; without PYTHONHOME it takes the prefix of the first python3
    on PATH, which may be a pyenv or a venv without them."""
    env = dict(os.environ)
    path = shutil.which(blender)
    if path and os.path.realpath(path).startswith("/usr/bin/") and "PYTHONHOME" not in env:
        env["PYTHONHOME"] = "/usr"
    return env


def launch(argv):
    a = parse_args(argv)
    try:
        frames = a.frames or default_frames(a)
        frame_list(frames)
    except ValueError:
        sys.exit("%s: --frames %s; expected A, A-B or A-BxSTEP" % (TOOL, a.frames))
    except (InputError, OSError) as e:
        print("%s: %s: %s" % (TOOL, a.scene, e), file=sys.stderr)
        sys.exit(1)
    inner = list(argv)
    if not a.frames:
        inner += ["--frames", frames]
    cmd = [a.blender, "-b", "--factory-startup", "--python", os.path.abspath(__file__), "--"]
    try:
        r = subprocess.run(cmd + inner, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           text=True, env=blender_environment(a.blender))
    except OSError as e:
        print("%s: %s: %s" % (TOOL, a.blender, e.strerror), file=sys.stderr)
        sys.exit(4)
    # Blender exits 0 even when the script fails; the script's last line says how it ended.
    lines = r.stdout.splitlines()
    status = [ln for ln in lines if ln.startswith(TOOL + " status ")]
    code = int(status[-1].split()[-1]) if status else 4
    for ln in lines:
        if ln.startswith(TOOL + ": ") or (code == 4 and "Error" in ln):
            print(ln, file=sys.stderr)
    if code == 4 and not status:
        print("%s: %s: blender ended without the script's status (exit %d)" %
              (TOOL, a.blender, r.returncode), file=sys.stderr)
    sys.exit(code)


# --- inside Blender


def gltf_json(path):
    """The glTF's JSON, from a .gltf or a .glb's first chunk."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] == b"glTF":
        length, kind = struct.unpack_from("<II", data, 12)
        if kind != 0x4E4F534A:
            raise InputError("glb without a JSON chunk first")
        data = data[20:20 + length]
    return json.loads(data.decode("utf-8"))


def check_scene(doc, a):
    """What this script cannot render as the stages do: refused, not approximated."""
    for anim in doc.get("animations", []):
        for s in anim.get("samplers", []):
            if s.get("interpolation") == "CUBICSPLINE":
                raise InputError("animation %s: CUBICSPLINE sampler (Blender's importer drops "
                                 "its tangents)" % anim.get("name", "?"))
    for cam in doc.get("cameras", []):
        ratio = cam.get("perspective", {}).get("aspectRatio")
        if ratio and abs(ratio - a.width / a.height) > 1e-6 * ratio:
            raise InputError("camera %s: aspectRatio %g differs from the image's %dx%d" %
                             (cam.get("name", "?"), ratio, a.width, a.height))


def camera_node_names(doc):
    """Camera node names in node order, as Scene::cameraNodes lists them (reachable nodes)."""
    nodes = doc.get("nodes", [])
    scenes = doc.get("scenes", [])
    roots = scenes[doc.get("scene", 0)].get("nodes", []) if scenes else []
    if not roots:
        children = {c for n in nodes for c in n.get("children", [])}
        roots = [i for i in range(len(nodes)) if i not in children]
    seen, stack = set(), list(roots)
    while stack:
        i = stack.pop()
        if 0 <= i < len(nodes) and i not in seen:
            seen.add(i)
            stack.extend(nodes[i].get("children", []))
    cams = doc.get("cameras", [])
    return [(nodes[i].get("name", ""), cams[nodes[i]["camera"]].get("name", ""))
            for i in sorted(seen) if "camera" in nodes[i]]


def choose_camera(bpy, doc, wanted):
    objects = [o for o in bpy.data.objects if o.type == "CAMERA"]
    names = camera_node_names(doc)
    for node_name, cam_name in names:
        if wanted and wanted not in (node_name, cam_name):
            continue
        for o in objects:
            if o.name == node_name or (not node_name and o.data.name == cam_name):
                return o
        if not wanted and len(objects) == 1:
            return objects[0]
    raise InputError("no camera %s" % (wanted or "in the scene"))


def link_or_copy(nt, src, dst, clamp=None):
    """dst takes what feeds src: its link, else its constant value (clamped per component)."""
    if src.is_linked:
        nt.links.new(src.links[0].from_socket, dst)
        return
    v = src.default_value
    try:
        values = list(v)
    except TypeError:
        dst.default_value = v
        return
    if clamp is not None:
        values = [min(x, clamp) for x in values[:3]] + values[3:]
    dst.default_value = values[:len(dst.default_value)]


def lambertian_material(mat):
    """Replaces the Principled BSDF by Diffuse + Emission, one-sided unless doubleSided."""
    nt = mat.node_tree
    out = next((n for n in nt.nodes if n.type == "OUTPUT_MATERIAL"), None)
    pbr = next((n for n in nt.nodes if n.type == "BSDF_PRINCIPLED"), None)
    if out is None or pbr is None:
        raise InputError("material %s: no Principled BSDF after import" % mat.name)
    diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Roughness"].default_value = 0.0
    link_or_copy(nt, pbr.inputs["Base Color"], diffuse.inputs["Color"], clamp=0.999)
    emission = nt.nodes.new("ShaderNodeEmission")
    link_or_copy(nt, pbr.inputs["Emission"], emission.inputs["Color"])
    link_or_copy(nt, pbr.inputs["Emission Strength"], emission.inputs["Strength"])
    front = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(diffuse.outputs["BSDF"], front.inputs[0])
    nt.links.new(emission.outputs["Emission"], front.inputs[1])
    surface = front.outputs["Shader"]
    if mat.use_backface_culling:  # the importer's mark of doubleSided false
        geometry = nt.nodes.new("ShaderNodeNewGeometry")
        light_path = nt.nodes.new("ShaderNodeLightPath")
        black = nt.nodes.new("ShaderNodeBsdfDiffuse")
        black.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        through = nt.nodes.new("ShaderNodeBsdfTransparent")
        through.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        back = nt.nodes.new("ShaderNodeMixShader")  # camera rays pass, others are absorbed
        nt.links.new(light_path.outputs["Is Camera Ray"], back.inputs["Fac"])
        nt.links.new(black.outputs["BSDF"], back.inputs[1])
        nt.links.new(through.outputs["BSDF"], back.inputs[2])
        sided = nt.nodes.new("ShaderNodeMixShader")
        nt.links.new(geometry.outputs["Backfacing"], sided.inputs["Fac"])
        nt.links.new(surface, sided.inputs[1])
        nt.links.new(back.outputs["Shader"], sided.inputs[2])
        surface = sided.outputs["Shader"]
    for link in list(out.inputs["Surface"].links):
        nt.links.remove(link)
    nt.links.new(surface, out.inputs["Surface"])


def setup_render(bpy, scene, a):
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = a.spp
    cy.use_adaptive_sampling = False
    cy.seed = a.seed
    cy.use_animated_seed = False
    cy.use_denoising = False
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.light_sampling_threshold = 0.0
    cy.max_bounces = a.max_bounces
    for kind in ("diffuse", "glossy", "transmission", "volume"):
        setattr(cy, kind + "_bounces", a.max_bounces)
    cy.transparent_max_bounces = max(a.max_bounces, 64)
    cy.pixel_filter_type = FILTERS[a.filter]
    cy.filter_width = a.filter_width
    cy.film_exposure = 1.0
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = a.width, a.height, 100
    r.pixel_aspect_x = r.pixel_aspect_y = 1.0
    r.use_border = False
    r.use_motion_blur = False
    r.film_transparent = False
    r.threads_mode = "FIXED" if a.threads else "AUTO"
    if a.threads:
        r.threads = a.threads
    vs = scene.view_settings
    vs.view_transform, vs.look, vs.exposure, vs.gamma = "Standard", "None", 0.0, 1.0
    im = r.image_settings
    im.file_format, im.color_mode, im.color_depth, im.exr_codec = "OPEN_EXR", "RGB", "32", "ZIP"
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    r.use_stamp_date = r.use_stamp_time = r.use_stamp_render_time = False
    r.use_stamp_frame = r.use_stamp_camera = r.use_stamp_lens = r.use_stamp_scene = False
    r.use_stamp_filename = r.use_stamp_memory = r.use_stamp_hostname = False
    r.use_stamp_marker = r.use_stamp_frame_range = False
    r.use_stamp_note = True  # the command line and what it resolved to, as EXR metadata
    command = " ".join(shlex.quote(x) for x in sys.argv[sys.argv.index("--") + 1:])
    r.stamp_note_text = ("%s %s; Blender %s, Cycles %s filter %g px, %d spp, seed %d, "
                         "%d bounces" % (TOOL, command, bpy.app.version_string,
                                         FILTERS[a.filter], a.filter_width, a.spp, a.seed,
                                         a.max_bounces))


def rotation_keys(fcurves):
    """The quaternion keys of an action: [(frame, (w, x, y, z))], or [] when not animated."""
    curves = sorted((fc for fc in fcurves if fc.data_path == "rotation_quaternion"),
                    key=lambda fc: fc.array_index)
    if len(curves) != 4:
        return []
    frames = [k.co[0] for k in curves[0].keyframe_points]
    return [(f, tuple(c.keyframe_points[i].co[1] for c in curves)) for i, f in enumerate(frames)]


def pose_at(bpy, scene, frame):
    """Evaluates the animation at `frame`, then freezes every object there with its rotation
    slerped between its keys (glTF's LINEAR rotation), its action removed."""
    from mathutils import Quaternion
    scene.frame_set(frame)
    for o in bpy.data.objects:
        ad = o.animation_data
        if not ad or not ad.action:
            continue
        loc, rot, scl = o.location.copy(), o.rotation_quaternion.copy(), o.scale.copy()
        keys = rotation_keys(ad.action.fcurves)
        interp = [k.interpolation for fc in ad.action.fcurves
                  if fc.data_path == "rotation_quaternion" for k in fc.keyframe_points]
        if keys and all(i == "LINEAR" for i in interp):
            for (f0, q0), (f1, q1) in zip(keys, keys[1:]):
                if f0 <= frame <= f1 and f1 > f0:
                    rot = Quaternion(q0).slerp(Quaternion(q1), (frame - f0) / (f1 - f0))
                    break
        ad.action = None
        o.rotation_mode = "QUATERNION"
        o.location, o.rotation_quaternion, o.scale = loc, rot, scl
    bpy.context.view_layer.update()


def render(a):
    import bpy
    doc = gltf_json(a.scene)
    check_scene(doc, a)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = a.fps, 1.0
    import numpy
    if not hasattr(numpy, "bool"):  # Blender 3.4's importer still says np.bool (numpy < 1.24)
        numpy.bool = bool
    bpy.ops.import_scene.gltf(filepath=os.path.abspath(a.scene), import_shading="NORMALS",
                              merge_vertices=False)
    for mat in bpy.data.materials:
        if mat.use_nodes and mat.users:
            lambertian_material(mat)
    scene.camera = choose_camera(bpy, doc, a.camera)
    setup_render(bpy, scene, a)
    os.makedirs(a.output, exist_ok=True)
    actions = {o.name: o.animation_data.action for o in bpy.data.objects
               if o.animation_data and o.animation_data.action}
    for f in frame_list(a.frames):
        for o in bpy.data.objects:  # restore the actions pose_at froze
            if o.name in actions:
                o.animation_data.action = actions[o.name]
        pose_at(bpy, scene, f)
        final = os.path.join(os.path.abspath(a.output), "%04d.exr" % f)
        partial = os.path.join(os.path.abspath(a.output), ".%04d.partial.exr" % f)
        scene.render.filepath = partial
        bpy.ops.render.render(write_still=True)
        os.replace(partial, final)
        print("%s: wrote %s" % (TOOL, final))


def inside_blender():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    code = 0
    try:
        render(parse_args(argv))
    except InputError as e:
        print("%s: %s: %s" % (TOOL, argv[0] if argv else "?", e))
        code = 1
    except SystemExit as e:  # argparse
        code = e.code if isinstance(e.code, int) else 2
    except Exception as e:  # noqa: BLE001 -- Blender would swallow it and exit 0
        import traceback
        traceback.print_exc(file=sys.stdout)
        print("%s: blender: %s" % (TOOL, e))
        code = 4
    print("%s status %d" % (TOOL, code))
    sys.stdout.flush()


if __name__ == "__main__":
    try:
        import bpy  # noqa: F401
    except ImportError:
        launch(sys.argv[1:])
    else:
        inside_blender()
