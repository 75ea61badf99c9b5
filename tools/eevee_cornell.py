# Blender (3.4) script for tools/eevee_compare.py: builds the engine's
# built-in Cornell box (engine/scene/builtin.c) in an empty scene and renders
# it with EEVEE, ambient occlusion (GTAO), soft shadows, bloom and depth of
# field at 1 sample, printing each render's wall time.
#   blender -b --factory-startup -P tools/eevee_cornell.py -- --size 512x384 --frames 3 --warmup 1
# The engine is y-up, Blender z-up: (x, y, z) becomes (x, -z, y); a turn about
# the engine's y is the same turn about Blender's z.
import argparse
import math
import sys
import time

import bpy

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
ap = argparse.ArgumentParser()
ap.add_argument("--size", default="512x384")
ap.add_argument("--frames", type=int, default=3)
ap.add_argument("--warmup", type=int, default=1)
ap.add_argument("--output", help="also write the last render here (PNG)")
args = ap.parse_args(argv)
width, height = (int(v) for v in args.size.split("x"))

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene


def material(name, rgb, specular=0.0, roughness=1.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*rgb, 1.0)
    bsdf.inputs["Specular"].default_value = specular
    bsdf.inputs["Roughness"].default_value = roughness
    return m


def b(p):  # engine point to Blender
    return (p[0], -p[2], p[1])


def quad(name, corners, mat):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([b(c) for c in corners], [], [(0, 1, 2, 3)])
    mesh.materials.append(mat)
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)


def box(name, centre, yaw_deg, size, mat):
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=b(centre), rotation=(0, 0, math.radians(yaw_deg)))
    obj = bpy.context.object
    obj.name = name
    obj.scale = (size[0], size[2], size[1])
    obj.data.materials.append(mat)


white = material("white", (0.73, 0.73, 0.73))
red = material("red", (0.63, 0.065, 0.05))
green = material("green", (0.14, 0.45, 0.091))
grey = material("box", (0.73, 0.73, 0.73), specular=0.15, roughness=0.4)
quad("floor", [(-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)], white)
quad("ceiling", [(-1, 2, -1), (1, 2, -1), (1, 2, 1), (-1, 2, 1)], white)
quad("back", [(-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1)], white)
quad("left", [(-1, 0, 1), (-1, 0, -1), (-1, 2, -1), (-1, 2, 1)], red)
quad("right", [(1, 0, -1), (1, 0, 1), (1, 2, 1), (1, 2, -1)], green)
box("short_box", (0.35, 0.3, 0.3), -17, (0.6, 0.6, 0.6), grey)
box("tall_box", (-0.35, 0.6, -0.35), 17, (0.6, 1.2, 0.6), grey)

light = bpy.data.lights.new("ceiling_light", type="POINT")
light.color = (1.0, 0.95, 0.85)
light.energy = 60.0
light.shadow_soft_size = 0.1  # soft shadows need an area
light_obj = bpy.data.objects.new("ceiling_light", light)
light_obj.location = b((0, 1.85, 0))
scene.collection.objects.link(light_obj)

cam = bpy.data.cameras.new("front")
cam.sensor_fit = "VERTICAL"
cam.angle_y = math.radians(45.0)
cam.clip_start, cam.clip_end = 0.1, 20.0
cam.dof.use_dof = True
cam.dof.focus_distance = 3.5  # the engine's dof.focus default
cam.dof.aperture_fstop = 0.5
cam_obj = bpy.data.objects.new("front", cam)
cam_obj.location = b((0, 1, 3.4))
cam_obj.rotation_euler = (math.radians(90), 0, 0)  # looks along Blender +y, the engine's -z
scene.collection.objects.link(cam_obj)
scene.camera = cam_obj

scene.render.engine = "BLENDER_EEVEE"
scene.render.resolution_x, scene.render.resolution_y = width, height
scene.render.resolution_percentage = 100
ee = scene.eevee
ee.taa_render_samples = 1
ee.gi_cubemap_resolution = "64"  # the world probe: the smallest, as the comparison's fair set-up
ee.use_gtao = True
ee.use_soft_shadows = True
ee.use_bloom = True
ee.bokeh_max_size = 8.0  # pixels, as the engine's dof.max_radius

times = []
for i in range(args.warmup + args.frames):
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=False)
    dt = (time.perf_counter() - t0) * 1000.0
    if i >= args.warmup:
        times.append(dt)
if args.output:
    bpy.data.images["Render Result"].save_render(args.output)
for t in times:
    print(f"eevee_frame_ms {t:.3f}")
