# tools/big_export.py: writes a big glTF export as Blender writes one (issue 35's "big scenes": a file whose
# size is its meshes', unlike data/scenes/big/big.glb, whose 1.54 M triangles share four meshes in 415 kB),
# for measuring load time and peak memory (`limn bench`, docs/benchmarks.md "Big files"). Write it outside
# the repository; it is about 76 MB:
#   blender -b -P tools/big_export.py -- /tmp/big_export.glb [SPHERES]
# SPHERES (default 420) UV spheres of 64 x 30 segments (3,712 triangles each, 1.56 M in all), each its own
# mesh, on a grid; one material with a 2048 x 2048 checker texture (16 MiB decoded); a sun and a camera.
import random
import sys

import bmesh
import bpy

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if not args:
    sys.exit("usage: blender -b -P tools/big_export.py -- OUT.glb [SPHERES]")
out, count = args[0], int(args[1]) if len(args) > 1 else 420
bpy.ops.wm.read_factory_settings(use_empty=True)
random.seed(4242)

bm = bmesh.new()
bm.loops.layers.uv.new("UVMap")  # create_uvsphere writes its uvs into the active layer
bmesh.ops.create_uvsphere(bm, u_segments=64, v_segments=30, radius=1.0, calc_uvs=True)
sphere = bpy.data.meshes.new("sphere")
bm.to_mesh(sphere)
bm.free()

side, cell = 2048, 64
image = bpy.data.images.new("checker", side, side)
pixels = []
for y in range(side):
    for x in range(side):
        v = 0.9 if (x // cell + y // cell) % 2 else 0.1
        pixels += (v, 0.5, 0.3, 1.0)
image.pixels.foreach_set(pixels)
image.pack()  # written into the .glb

material = bpy.data.materials.new("checker")
material.use_nodes = True
texture = material.node_tree.nodes.new("ShaderNodeTexImage")
texture.image = image
material.node_tree.links.new(texture.outputs["Color"], material.node_tree.nodes["Principled BSDF"].inputs["Base Color"])

columns = max(1, int(count ** 0.5))
for k in range(count):
    mesh = sphere.copy()  # its own mesh: the file holds every sphere's vertices
    mesh.materials.append(material)
    ball = bpy.data.objects.new("ball%d" % k, mesh)
    ball.location = ((k % columns) * 3.0 - 1.5 * columns, (k // columns) * 3.0 - 1.5 * columns, random.random())
    bpy.context.scene.collection.objects.link(ball)
sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
bpy.context.scene.collection.objects.link(sun)
camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
camera.location = (0, -2.0 * columns, 1.3 * columns)
camera.rotation_euler = (0.9, 0, 0)
bpy.context.scene.collection.objects.link(camera)
bpy.ops.export_scene.gltf(filepath=out, export_format="GLB", export_lights=True, export_cameras=True)
