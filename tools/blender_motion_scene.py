# Blender (3.4) script for tools/blender_motion_check.sh: builds a small scene
# that moves (a floor, a box keyed with Blender's default Bezier keys on
# location, rotation and scale, a box with linear location and constant
# rotation keys, a box keyed with quaternions, a camera dolly, a sun), exports it with Blender's own glTF
# exporter (its defaults: sampled animation, y-up) and writes, at each of the
# given times, every object's world matrix as Blender evaluates it, and as
# the export's per-frame samples hold it, carried into glTF's space, to
# poses.json; with --render also a Workbench frame (flat object colours, no
# anti-aliasing) of each time, blender_N.png.
#   blender -b --factory-startup -P tools/blender_motion_scene.py -- --out DIR --times 0,0.5,1 [--render]
#     [--unsampled]  (the keys as they are: Bezier as CUBICSPLINE; no samples in poses.json)
# glTF is y-up, Blender z-up: the exporter maps (x, y, z) to (x, z, -y) (C, a
# -90 degree turn about x). A mesh's vertices go through C as well, so its
# node's world matrix is C M C^-1; a camera or light keeps its own axes (both
# look down their -z), so its node's is C M.
import argparse
import json
import math
import os
import sys

import bpy
from mathutils import Matrix, Quaternion

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
ap = argparse.ArgumentParser()
ap.add_argument("--out", required=True)
ap.add_argument("--times", default="0,0.5,1,1.37,2")
ap.add_argument("--fps", type=int, default=24)
ap.add_argument("--size", default="160x120")
ap.add_argument("--render", action="store_true")
ap.add_argument("--unsampled", action="store_true", help="export keys as they are, not sampled each frame")
args = ap.parse_args(argv)
times = [float(t) for t in args.times.split(",")]
width, height = (int(v) for v in args.size.split("x"))
os.makedirs(args.out, exist_ok=True)

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = args.fps
scene.render.fps_base = 1.0
scene.frame_start = 0  # glTF time 0 is frame 0
scene.frame_end = 2 * args.fps
scene.render.resolution_x, scene.render.resolution_y = width, height
scene.render.resolution_percentage = 100


def keys(obj, path, frames_values, interpolation=None):
    """Keys obj.<path> at each (frame, value); interpolation None keeps Blender's default (Bezier)."""
    for frame, value in frames_values:
        setattr(obj, path, value)
        obj.keyframe_insert(data_path=path, frame=frame)
    if interpolation:
        for fc in obj.animation_data.action.fcurves:
            if fc.data_path == path:
                for k in fc.keyframe_points:
                    k.interpolation = interpolation


def coloured(obj, name, colour):
    """The object's colour (Workbench renders it flat) and a material emitting it, black otherwise
    (the export carries it: Limn renders it flat too)."""
    obj.name = name
    obj.color = (*colour, 1.0)
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    bsdf.inputs["Specular"].default_value = 0.0
    bsdf.inputs["Emission"].default_value = (*colour, 1.0)
    bsdf.inputs["Emission Strength"].default_value = 1.0
    obj.data.materials.append(m)
    return obj


def box(name, colour):
    bpy.ops.mesh.primitive_cube_add(size=1.0)
    return coloured(bpy.context.object, name, colour)


bpy.ops.mesh.primitive_plane_add(size=8.0)
floor = coloured(bpy.context.object, "floor", (0.2, 0.2, 0.2))

f = args.fps
bezier = box("box_bezier", (1.0, 0.3, 0.3))
keys(bezier, "location", [(0, (-1.5, 0.0, 0.5)), (f, (-0.5, 1.0, 1.2)), (2 * f, (0.5, 0.0, 0.5))])
keys(bezier, "rotation_euler", [(0, (0.0, 0.0, 0.0)), (f, (0.3, 0.6, 1.2)), (2 * f, (0.0, 0.0, 2.5))])
keys(bezier, "scale", [(0, (1.0, 1.0, 1.0)), (f, (1.2, 0.8, 1.0)), (2 * f, (0.7, 0.7, 1.4))])

linear = box("box_linear", (0.3, 0.3, 1.0))
keys(linear, "location", [(0, (1.5, -1.0, 0.4)), (20, (1.5, 1.0, 0.4)), (40, (1.0, 0.0, 0.9))], "LINEAR")
keys(linear, "rotation_euler", [(0, (0.0, 0.0, 0.0)), (20, (0.0, 0.0, 0.8)), (40, (0.0, 0.0, 1.6))], "CONSTANT")

# Keyed as quaternions (Bezier on each component, normalized), as glTF keys rotations.
quat = box("box_quat", (0.3, 1.0, 0.3))
quat.rotation_mode = "QUATERNION"
keys(quat, "location", [(0, (0.0, -2.0, 0.5)), (2 * f, (0.0, -2.0, 0.5))])
keys(quat, "rotation_quaternion", [(0, Quaternion()), (f, Quaternion((0.3, 0.2, 1.0), 1.4)),
                                   (2 * f, Quaternion((1.0, 0.0, 0.2), 2.6))])

cam_data = bpy.data.cameras.new("camera")
camera = bpy.data.objects.new("camera", cam_data)
scene.collection.objects.link(camera)
scene.camera = camera
keys(camera, "location", [(0, (0.0, -9.0, 3.5)), (2 * f, (0.5, -5.5, 2.4))])
keys(camera, "rotation_euler", [(0, (math.radians(72), 0.0, 0.0)), (2 * f, (math.radians(76), 0.0, math.radians(5)))])

sun_data = bpy.data.lights.new("sun", type="SUN")
sun_data.energy = 3.0
sun = bpy.data.objects.new("sun", sun_data)
sun.rotation_euler = (0.6, 0.0, 0.3)  # from behind the camera: the faces it sees are lit
scene.collection.objects.link(sun)

glb = os.path.join(args.out, "motion.glb")
bpy.ops.export_scene.gltf(filepath=glb, export_format="GLB", export_cameras=True, export_lights=True,
                          export_force_sampling=not args.unsampled)

C = Matrix.Rotation(-math.pi / 2, 4, "X")
objects = [floor, bezier, linear, quat, camera, sun]


def set_frame(frame):
    """Poses the scene at a frame, fractions included (renders take the fraction too)."""
    scene.frame_set(int(math.floor(frame)), subframe=frame - math.floor(frame))


def world_matrices(frame):
    """Each object's world matrix (Blender's space) at a frame."""
    set_frame(frame)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    return [o.evaluated_get(depsgraph).matrix_world.copy() for o in objects]


def sampled(at, before, after, a):
    """What the export holds between two frames `a` of the way: the frames' samples, interpolated
    linearly (slerp for rotations), or held where Blender held (a constant key, exported as STEP)."""
    parts = []
    for now, m0, m1 in zip(at.decompose(), before.decompose(), after.decompose()):
        if all(abs(x - y) < 1e-9 for x, y in zip(now, m0)):
            parts.append(m0)
        elif len(m0) == 4:
            parts.append(m0.slerp(m1, a))
        else:
            parts.append(m0.lerp(m1, a))
    loc, rot, scale = parts
    return Matrix.LocRotScale(loc, rot, scale)


def gltf_space(o, m):
    return C @ m @ C.inverted() if o.type == "MESH" else C @ m


def column_major(m):
    return [m[r][c] for c in range(4) for r in range(4)]


poses = {o.name: [] for o in objects}
samples = {o.name: [] for o in objects}
for t in times:
    frame = t * f
    exact = world_matrices(frame)
    a = frame - math.floor(frame)
    if a > 1e-9:
        before, after = world_matrices(math.floor(frame)), world_matrices(math.floor(frame) + 1)
        held = [sampled(m, m0, m1, a) for m, m0, m1 in zip(exact, before, after)]
    else:
        held = exact
    for o, m, h in zip(objects, exact, held):
        poses[o.name].append(column_major(gltf_space(o, m)))
        samples[o.name].append(column_major(gltf_space(o, h)))

# The vertical field of view Blender renders with (sensor fit AUTO: the
# sensor's width spans the longer side).
aspect = width / height
fov_x = 2 * math.atan(cam_data.sensor_width / 2 / cam_data.lens)
fov_y = fov_x if height > width else 2 * math.atan(math.tan(fov_x / 2) / aspect)
with open(os.path.join(args.out, "poses.json"), "w") as out:
    json.dump({"blender": bpy.app.version_string, "fps": f, "times": times, "glb": glb,
               "camera": {"name": camera.name, "fov_y": fov_y, "aspect": aspect}, "nodes": poses,
               "sampled": None if args.unsampled else samples}, out, indent=1)

if args.render:
    scene.render.engine = "BLENDER_WORKBENCH"
    shading = scene.display.shading
    shading.light = "FLAT"
    shading.color_type = "OBJECT"
    scene.display.render_aa = "OFF"  # one sample a pixel, as Limn draws: no blended edge pixels
    scene.world = bpy.data.worlds.new("black")
    scene.world.color = (0.0, 0.0, 0.0)
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "PNG"
    for i, t in enumerate(times):
        set_frame(t * f)
        scene.render.filepath = os.path.join(args.out, "blender_%d.png" % i)
        bpy.ops.render.render(write_still=True)
