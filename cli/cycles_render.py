# Renders Limn views with Blender's Cycles, the path-traced references of
# `limn reference --renderer cycles` (docs/cycles.md states the mapping):
#
#   blender -b --factory-startup -noaudio --python-exit-code 1 \
#           --python cli/cycles_render.py -- SPEC.json OUT.exr [SPEC.json OUT.exr ...]
#
# Several pairs in one run save Blender's start (seconds) a view; each fails
# or renders on its own, and the run exits 1 when any failed. With
# $LIMN_PROGRESS_FD set (limn reference), the pair's index (0, 1, ...) and a
# newline are written to that file descriptor as each OUT is complete.
#
# SPEC.json, one object (every key required unless marked optional):
#   scene      absolute path of the .glb/.gltf file (Limn's coordinates: +Y up)
#   camera     {"eye": [x,y,z], "target": [x,y,z], "up": [x,y,z], "fov_y": degrees}
#   width, height   output size in pixels (1..65536)
#   samples    paths a pixel (1..1048576); bounces: diffuse (and glossy and
#              transmission) bounces, 0..1024, 0 = direct light only
#   seed       Cycles' seed (0..2^31-1)
#   materials  "phong" (Limn's std technique) or "pbr" (glTF metallic-roughness)
#   view       the view's name, for messages
#   sky        null, or sky.lua's parameters:
#                {"zenith": [r,g,b] or x, "horizon": [r,g,b] or x,
#                 "intensity": x (optional, 1), "map": "" or an absolute path
#                 of an equirectangular HDR (top row the zenith, the middle
#                 column looking along -Z)}
#   ambient    optional: Limn's uniform ambient radiance ([r,g,b] or x, 0 when
#              absent), added to the sky as a uniform sky of that radiance
#   time       optional: seconds into the file's animation (0 when absent);
#              Blender's importer plays the file's first animation only
#
# OUT.exr: linear RGB float OpenEXR (32-bit), rendered under a temporary name
# in OUT's folder and renamed on success. Errors print one line naming the
# view and the part ("limn cycles: view 'v': scene x.glb: ...") and exit 1.
import json
import math
import os
import re
import struct
import sys
import tempfile
import warnings

import bpy

try:
    import numpy  # Blender's glTF importer needs it too; Debian's blender does not depend on it
except ImportError:
    print("limn cycles: Blender's Python has no numpy: install Debian's python3-numpy "
          "(apt-get install python3-numpy)", file=sys.stderr)
    sys.exit(1)

PREFIX = "limn cycles"
VIEW = "?"
WARNED = set()

# glTF extensions Limn reads (engine/scene/gltf.h); a file requiring another is refused.
GLASS_EXTENSIONS = ("KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume")  # glass_of
KNOWN_REQUIRED = {"KHR_lights_punctual", "KHR_texture_transform", "KHR_materials_emissive_strength", *GLASS_EXTENSIONS}
PBR_MIN_ROUGHNESS = 0.08  # shaders/gbuffer.glsl
# Limn's material for a primitive without one (engine/scene/scene.c's fallback).
DEFAULT_PHONG = {"color": (0.8, 0.8, 0.8), "kd": 0.9, "ks": 0.0, "shininess": 16.0}


class SpecError(Exception):
    pass


def fail(part, msg):
    raise SpecError("%s: %s" % (part, msg))


def warn(key, msg):
    if key not in WARNED:
        WARNED.add(key)
        print("%s: view '%s': warning: %s" % (PREFIX, VIEW, msg), file=sys.stderr)


# ---------------------------------------------------------------- spec


def number(spec, key, lo, hi, integer=False, part=None):
    v = spec.get(key)
    name = part or key
    span = ("%d..%d" if integer else "%g..%g") % (lo, hi)
    if (isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v)
            or (integer and v != int(v)) or not (lo <= v <= hi)):
        fail(name, "wants %s in %s, not %s" % ("an integer" if integer else "a number", span, json.dumps(v)))
    return int(v) if integer else float(v)


def vec3(v, name):
    if (not isinstance(v, list) or len(v) != 3
            or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v)):
        fail(name, "wants [x, y, z] (3 finite numbers), not %s" % json.dumps(v))
    return [float(x) for x in v]


def colour(v, name):
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        v = [v, v, v]
    c = vec3(v, name) if isinstance(v, list) else None
    if c is None or not all(0.0 <= x <= 1e6 for x in c):
        fail(name, "wants [r, g, b] or one number, each in 0..1e6, not %s" % json.dumps(v))
    return c


def read_spec(path):
    try:
        with open(path, encoding="utf-8") as f:
            spec = json.load(f)
    except (OSError, ValueError) as e:
        fail("spec %s" % path, str(e))
    if not isinstance(spec, dict):
        fail("spec %s" % path, "wants a JSON object")
    global VIEW
    VIEW = str(spec.get("view", "?"))
    known = {"scene", "camera", "width", "height", "samples", "bounces", "seed", "materials", "view", "sky",
             "ambient", "time"}
    for k in spec:
        if k not in known:
            fail("spec", "unknown key '%s' (known: %s)" % (k, ", ".join(sorted(known))))
    s = {"view": VIEW}
    scene = spec.get("scene")
    if not isinstance(scene, str) or not os.path.isabs(scene) or not re.search(r"\.(glb|gltf)$", scene, re.I):
        fail("scene", "wants the absolute path of a .glb or .gltf file, not %s" % json.dumps(scene))
    if not os.path.isfile(scene):
        fail("scene %s" % scene, "no such file")
    s["scene"] = scene
    cam = spec.get("camera")
    if not isinstance(cam, dict):
        fail("camera", "wants {eye, target, up, fov_y}")
    s["eye"] = vec3(cam.get("eye"), "camera.eye")
    s["target"] = vec3(cam.get("target"), "camera.target")
    s["up"] = vec3(cam.get("up"), "camera.up")
    s["fov_y"] = number(cam, "fov_y", 1e-3, 179.0, part="camera.fov_y")
    forward = [t - e for t, e in zip(s["target"], s["eye"])]
    if norm(forward) < 1e-9 or norm(cross(forward, s["up"])) < 1e-9 * norm(forward) * max(norm(s["up"]), 1e-30):
        fail("camera", "eye and target coincide, or up is parallel to the view direction")
    s["width"] = number(spec, "width", 1, 65536, True)
    s["height"] = number(spec, "height", 1, 65536, True)
    s["samples"] = number(spec, "samples", 1, 1 << 20, True)
    s["bounces"] = number(spec, "bounces", 0, 1024, True)
    s["seed"] = number(spec, "seed", 0, 2**31 - 1, True)
    if spec.get("materials") not in ("phong", "pbr"):
        fail("materials", 'wants "phong" or "pbr", not %s' % json.dumps(spec.get("materials")))
    s["materials"] = spec["materials"]
    s["ambient"] = colour(spec["ambient"], "ambient") if "ambient" in spec else [0.0, 0.0, 0.0]
    s["time"] = number(spec, "time", -1e6, 1e6) if "time" in spec else 0.0
    sky = spec.get("sky")
    if sky is None:
        s["sky"] = None
    elif not isinstance(sky, dict):
        fail("sky", "wants null or {zenith, horizon, intensity, map}")
    else:
        for k in sky:
            if k not in ("zenith", "horizon", "intensity", "map"):
                fail("sky", "unknown key '%s' (known: zenith, horizon, intensity, map)" % k)
        m = sky.get("map", "")
        if not isinstance(m, str) or (m and not os.path.isabs(m)):
            fail("sky.map", "wants \"\" or an absolute path, not %s" % json.dumps(m))
        if m and not os.path.isfile(m):
            fail("sky.map %s" % m, "no such file")
        s["sky"] = {
            "zenith": colour(sky.get("zenith", [0.1, 0.15, 0.3]), "sky.zenith"),
            "horizon": colour(sky.get("horizon", [0.3, 0.32, 0.35]), "sky.horizon"),
            "intensity": number(sky, "intensity", 0, 1e6, part="sky.intensity") if "intensity" in sky else 1.0,
            "map": m,
        }
    return s


def norm(a):
    return math.sqrt(sum(x * x for x in a))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def to_blender(p):
    """glTF's +Y up to Blender's +Z up, as Blender's glTF importer turns it."""
    return [p[0], -p[2], p[1]]


# ---------------------------------------------------------------- glTF


def read_gltf(path):
    """The file's JSON and, for .glb, its binary chunk (None for .gltf)."""
    part = "scene %s" % path
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as e:
        fail(part, str(e))
    if data[:4] == b"glTF":
        if len(data) < 20:
            fail(part, "truncated GLB header")
        _, _, length = struct.unpack_from("<III", data, 0)
        jlen, jtype = struct.unpack_from("<II", data, 12)
        if jtype != 0x4E4F534A or 20 + jlen > len(data) or length > len(data):
            fail(part, "bad GLB: the JSON chunk is missing or runs past the file's end")
        text, rest = data[20:20 + jlen], data[20 + jlen:]
    else:
        text, rest = data, None
    try:
        doc = json.loads(text.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as e:
        fail(part, "not glTF JSON: %s" % e)
    if not isinstance(doc, dict) or not isinstance(doc.get("asset"), dict):
        fail(part, "not glTF 2.0 (no asset)")
    return doc, rest


def check_and_tag(doc, path):
    """Refuses what cannot be mapped, warns what is approximate, and names
    materials and lights by index (limn_m<i>, limn_l<i>) so that the imported
    Blender data can be found again. Returns the lights' list."""
    part = "scene %s" % path
    for e in doc.get("extensionsRequired", []):
        if e not in KNOWN_REQUIRED:
            fail(part, "requires extension %s, which the Cycles export does not take (limn export-gltf writes "
                 "a copy without it)" % e)
    materials = doc.get("materials", [])
    for i, m in enumerate(materials):
        m["name"] = "limn_m%d" % i
        for e in m.get("extensions", {}):
            if e not in ("KHR_materials_emissive_strength", "KHR_texture_transform") + GLASS_EXTENSIONS:
                warn("ext " + e, "%s: material %d uses %s, which Limn ignores: ignored here too" % (part, i, e))
    lights = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    for i, l in enumerate(lights):
        l["name"] = "limn_l%d" % i
    return lights


def write_tagged(doc, binary, path, folder):
    """The tagged copy for Blender's importer: a .glb with the same binary
    chunk, or a .gltf whose relative URIs now point beside the original."""
    base = os.path.dirname(path)
    if binary is None:
        for key in ("buffers", "images"):
            for item in doc.get(key, []):
                uri = item.get("uri")
                if isinstance(uri, str) and not uri.startswith("data:") and "://" not in uri:
                    item["uri"] = os.path.join(base, uri)
        out = os.path.join(folder, "scene.gltf")
        with open(out, "w", encoding="utf-8") as f:
            json.dump(doc, f)
        return out
    text = json.dumps(doc).encode("utf-8")
    text += b" " * (-len(text) % 4)
    out = os.path.join(folder, "scene.glb")
    with open(out, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + len(binary)))
        f.write(struct.pack("<II", len(text), 0x4E4F534A))
        f.write(text)
        f.write(binary)
    return out


def import_scene(spec, folder):
    path = spec["scene"]
    doc, binary = read_gltf(path)
    lights = check_and_tag(doc, path)
    if len(doc.get("animations", [])) > 1:
        warn("animations", "scene %s: %d animations: Blender's importer plays the first only (Limn all of them)"
             % (path, len(doc["animations"])))
    tagged = write_tagged(doc, binary, path, folder)
    # An empty start: the factory scene's cube, light and camera, or the previous view's scene.
    for kind in ("objects", "meshes", "materials", "lights", "cameras", "images", "worlds", "node_groups",
                 "actions", "textures", "armatures", "collections"):
        blocks = getattr(bpy.data, kind)
        for block in list(blocks):
            if getattr(block, "type", None) != "RENDER_RESULT":
                blocks.remove(block)
    # Blender 3.4's importer names numpy.bool, which numpy 1.24 (Debian 12's) removed.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if not hasattr(numpy, "bool"):
            numpy.bool = bool
    try:
        result = bpy.ops.import_scene.gltf(filepath=tagged, convert_lighting_mode="SPEC")
    except Exception as e:  # the importer raises what it meets: name the file and the error, not the traceback
        lines = [x for x in str(e).splitlines() if x.strip() and not x.startswith((" ", "Location:"))]
        fail("scene %s" % path, "Blender cannot import it: %s" % (lines[-1] if lines else "no reason given"))
    if "FINISHED" not in result:
        fail("scene %s" % path, "Blender cannot import it (%s)" % ", ".join(result))
    return doc, lights


# ---------------------------------------------------------------- lights


def map_lights(lights):
    """Punctual lights stay punctual (radius and angle 0). Blender's importer
    converts the units (SPEC mode: W = cd * 4 pi / 683, W/m^2 = lux / 683);
    the spot's smooth edge is set so that Cycles' smoothstep over the cosine
    runs from cos(outer) to cos(inner), as Limn's does; a range gets Limn's
    window (range_window)."""
    for obj in bpy.context.scene.objects:
        if obj.type != "LIGHT":
            continue
        light = obj.data
        m = re.match(r"limn_l(\d+)", light.name)
        if not m or int(m.group(1)) >= len(lights):
            fail("light '%s'" % light.name, "not one of the file's KHR_lights_punctual lights")
        gl = lights[int(m.group(1))]
        if light.type == "SUN":
            light.angle = 0.0
        else:
            light.shadow_soft_size = 0.0
        if light.type == "SPOT":
            cone = gl.get("spot", {})
            outer = cone.get("outerConeAngle", math.pi / 4)
            inner = cone.get("innerConeAngle", 0.0)
            co, ci = math.cos(outer), math.cos(min(inner, outer))
            light.spot_size = 2.0 * outer
            light.spot_blend = (ci - co) / (1.0 - co) if co < 1.0 else 0.0
            unfold_spot(light)
        if light.type in ("POINT", "SPOT") and gl.get("range", 0) > 0:
            range_window(light, float(gl["range"]))


def scale_strength(light):
    """The light's node tree (made when it has none) and a Multiply node
    whose first input is what fed its Emission's Strength and whose output
    now feeds it: link or set a factor into its second input."""
    light.use_nodes = True
    nodes, links = light.node_tree.nodes, light.node_tree.links
    strength = next(n for n in nodes if n.type == "EMISSION").inputs["Strength"]
    product = nodes.new("ShaderNodeMath")
    product.operation = "MULTIPLY"
    if strength.is_linked:
        links.new(strength.links[0].from_socket, product.inputs[0])
    else:
        product.inputs[0].default_value = strength.default_value
    links.new(product.outputs[0], strength)
    return nodes, links, product.inputs[1]


def range_window(light, reach):
    """KHR_lights_punctual's range as Limn windows it (engine/scene/scene.c
    lm_light_falloff): the light times clamp(1 - (d / range)^4, 0, 1) over
    its 1/d^2, d the distance from the light, which Cycles gives a light's
    shader as the Light Path's Ray Length."""
    nodes, links, factor = scale_strength(light)
    path = nodes.new("ShaderNodeLightPath")
    ratio = nodes.new("ShaderNodeMath")
    ratio.operation = "DIVIDE"
    links.new(path.outputs["Ray Length"], ratio.inputs[0])
    ratio.inputs[1].default_value = reach
    fourth = nodes.new("ShaderNodeMath")
    fourth.operation = "POWER"
    links.new(ratio.outputs[0], fourth.inputs[0])
    fourth.inputs[1].default_value = 4.0
    window = nodes.new("ShaderNodeMath")
    window.operation, window.use_clamp = "SUBTRACT", True
    window.inputs[0].default_value = 1.0
    links.new(fourth.outputs[0], window.inputs[1])
    links.new(window.outputs[0], factor)


def unfold_spot(light):
    """Cycles 3.4 weighs a spot's light by the cosine to its axis as well as
    by the cone's smoothstep; KHR_lights_punctual (and Limn) by the cone
    alone: the light's strength is divided by that cosine (the light's local
    -Z, its Normal coordinate; at least cos(outer) inside the cone, and the
    division kept finite outside it)."""
    nodes, links, factor = scale_strength(light)
    coords = nodes.new("ShaderNodeTexCoord")
    split = nodes.new("ShaderNodeSeparateXYZ")
    links.new(coords.outputs["Normal"], split.inputs[0])
    cosine = nodes.new("ShaderNodeMath")
    cosine.operation = "MULTIPLY"
    links.new(split.outputs["Z"], cosine.inputs[0])
    cosine.inputs[1].default_value = -1.0
    floor = nodes.new("ShaderNodeMath")
    floor.operation = "MAXIMUM"
    links.new(cosine.outputs[0], floor.inputs[0])
    floor.inputs[1].default_value = 1e-3
    inverse = nodes.new("ShaderNodeMath")
    inverse.operation = "DIVIDE"
    inverse.inputs[0].default_value = 1.0
    links.new(floor.outputs[0], inverse.inputs[1])
    links.new(inverse.outputs[0], factor)


# ---------------------------------------------------------------- materials


class Tree:
    """Small helpers over a material's node tree."""

    def __init__(self, mat):
        self.nodes, self.links = mat.node_tree.nodes, mat.node_tree.links

    def node(self, kind, **inputs):
        n = self.nodes.new(kind)
        for k, v in inputs.items():
            self.set(n.inputs[k], v)
        return n

    def set(self, socket, v):
        if hasattr(v, "links") or hasattr(v, "is_output"):  # a socket
            self.links.new(v, socket)
        elif isinstance(v, (int, float)) and socket.type in ("RGBA", "VECTOR"):
            socket.default_value = (v, v, v, 1.0)[:len(socket.default_value)]
        elif isinstance(v, (list, tuple)) and socket.type == "RGBA" and len(v) == 3:
            socket.default_value = (v[0], v[1], v[2], 1.0)
        else:
            socket.default_value = v

    def math(self, op, a, b=0.0, clamp=False):
        n = self.node("ShaderNodeMath")
        n.operation, n.use_clamp = op, clamp
        self.set(n.inputs[0], a)
        self.set(n.inputs[1], b)
        return n.outputs[0]

    def mix(self, blend, fac, a, b, clamp=False):
        n = self.node("ShaderNodeMixRGB")
        n.blend_type, n.use_clamp = blend, clamp
        self.set(n.inputs["Fac"], fac)
        self.set(n.inputs["Color1"], a)
        self.set(n.inputs["Color2"], b)
        return n.outputs[0]

    def source(self, socket):
        """What feeds an input socket: the linked output, or its value."""
        if socket.is_linked:
            return socket.links[0].from_socket
        v = socket.default_value
        return tuple(v)[:3] if hasattr(v, "__len__") else float(v)


def phong_values(gm):
    """Limn's Phong material of glTF material gm (engine/scene/gltf.h)."""
    pbr = gm.get("pbrMetallicRoughness", {}) if gm is not None else None
    if pbr is None:
        return DEFAULT_PHONG
    color = [min(max(c, 0.0), 1.0) for c in pbr.get("baseColorFactor", [1, 1, 1, 1])[:3]]
    metallic = min(max(pbr.get("metallicFactor", 1.0), 0.0), 1.0)
    r = min(max(pbr.get("roughnessFactor", 1.0), 0.0), 1.0)
    shininess = 1024.0 if r ** 4 <= 2.0 / 1026.0 else min(max(2.0 / r ** 4 - 2.0, 1.0), 1024.0)
    return {"color": color, "kd": 1.0 - metallic, "ks": 0.04 + (max(color) - 0.04) * metallic,
            "shininess": shininess}


def glossy_of_phong(shininess):
    """Blender's GGX roughness for a Phong exponent n on (r.v): Phong n is
    about Blinn-Phong 4n, whose lobe matches GGX alpha^2 = 2 / (4n + 2);
    Blender's roughness is sqrt(alpha)."""
    return (1.0 / (2.0 * shininess + 1.0)) ** 0.25


def build_phong(t, base, pv, keep=1.0):
    """Lambert k_d albedo + a GGX lobe carrying the Phong lobe's energy at
    normal incidence, 2 k_s / (n + 2) (Limn's Phong is not normalized). The
    geometric normal: Limn's std technique reads no normal map. `keep`: the
    share of the diffuse part glass does not transmit (glass_of)."""
    albedo = t.mix("MULTIPLY", 1.0, base, 1.0, clamp=True)
    diffuse = t.node("ShaderNodeBsdfDiffuse", Color=t.mix("MULTIPLY", 1.0, albedo, pv["kd"] * keep), Roughness=0.0)
    if pv["ks"] <= 0.0:
        return diffuse.outputs[0]
    n = pv["shininess"]
    glossy = t.node("ShaderNodeBsdfGlossy", Color=2.0 * pv["ks"] / (n + 2.0), Roughness=glossy_of_phong(n))
    glossy.distribution = "GGX"
    warn("phong", "materials=phong: Phong's specular lobe (k_s (r.v)^n) is approximated by a GGX lobe of "
         "the same energy at normal incidence (docs/cycles.md)")
    return add(t, diffuse.outputs[0], glossy.outputs[0])


def add(t, a, b):
    n = t.node("ShaderNodeAddShader")
    t.links.new(a, n.inputs[0])
    t.links.new(b, n.inputs[1])
    return n.outputs[0]


def build_pbr(t, base, metallic, roughness, normal, keep=1.0):
    """glTF's BRDF: Lambert (1 - F)(1 - metallic) base + GGX with F at v.h,
    F0 = mix(0.04, base, metallic). The GGX lobe is Blender's Principled BSDF
    at metallic 1 and base F0: its Fresnel runs from F0 at v.h = 1 to 1 at
    grazing (a dielectric's curve of ior 1.5 rescaled, not Schlick's), and
    its diffuse part is 0. Nodes do not see v.h: the diffuse weight is
    1 - F0, F where light and view meet head on (docs/cycles.md). `keep`:
    the share of the diffuse part glass does not transmit (glass_of)."""
    base = t.mix("MULTIPLY", 1.0, base, 1.0, clamp=True)
    metallic = t.math("MULTIPLY", metallic, 1.0, clamp=True)
    rough = t.math("MAXIMUM", t.math("MULTIPLY", roughness, 1.0, clamp=True), PBR_MIN_ROUGHNESS)
    f0 = t.mix("MIX", metallic, 0.04, base)
    kept = t.math("MULTIPLY", t.math("SUBTRACT", 1.0, metallic), keep)
    diffuse_colour = t.mix("MULTIPLY", 1.0, t.mix("MULTIPLY", 1.0, base, kept), t.mix("SUBTRACT", 1.0, 1.0, f0))
    diffuse = t.node("ShaderNodeBsdfDiffuse", Color=diffuse_colour, Roughness=0.0)
    specular = t.node("ShaderNodeBsdfPrincipled", **{"Base Color": f0, "Metallic": 1.0, "Roughness": rough,
                                                     "Specular": 0.5})
    specular.distribution = "GGX"  # single scattering, as glTF's
    for n in (diffuse, specular):
        if normal is not None:
            t.set(n.inputs["Normal"], normal)
    return add(t, diffuse.outputs[0], specular.outputs[0])


def glass_of(gm):
    """Limn's glass (engine/scene/gltf.h): KHR_materials_transmission's
    factor t, KHR_materials_ior's ior and KHR_materials_volume's absorption
    at normal incidence, attenuationColor ^ (thickness / attenuationDistance);
    None for no transmission (or a MASK material, which Limn draws opaque)."""
    ext = gm.get("extensions", {}) if gm else {}
    t = ext.get("KHR_materials_transmission", {}).get("transmissionFactor", 0.0)
    if t <= 0.0 or gm.get("alphaMode") == "MASK":
        return None
    vol = ext.get("KHR_materials_volume", {})
    thick, dist = vol.get("thicknessFactor", 0.0), vol.get("attenuationDistance", 0.0)
    absorbed = [c ** (thick / dist) if thick > 0.0 and dist > 0.0 else 1.0
                for c in vol.get("attenuationColor", [1.0, 1.0, 1.0])]
    return t, ext.get("KHR_materials_ior", {}).get("ior", 1.5), absorbed


def schlick(t, ior):
    """Limn's Fresnel (shaders/transparent.frag): Schlick's r0 + (1 - r0)(1 - |n.v|)^5
    of the ior, the same from either side. (Blender's Fresnel node inverts the
    ior from behind, whose total internal reflection would stop the shadow
    rays that reach a surface through the glass.)"""
    r0 = ((ior - 1.0) / (ior + 1.0)) ** 2
    geometry = t.node("ShaderNodeNewGeometry")
    dot = t.node("ShaderNodeVectorMath")
    dot.operation = "DOT_PRODUCT"
    t.links.new(geometry.outputs["Normal"], dot.inputs[0])
    t.links.new(geometry.outputs["Incoming"], dot.inputs[1])
    grazing = t.math("SUBTRACT", 1.0, t.math("ABSOLUTE", dot.outputs["Value"]))
    return t.math("ADD", t.math("MULTIPLY", t.math("POWER", grazing, 5.0), 1.0 - r0), r0)


def add_glass(t, shader, base, glass):
    """What Limn's forward pass lets through (shaders/transparent.frag): a
    Transparent BSDF (rays pass straight, unrefracted, as Limn's) of colour
    t (1 - F) base absorbed, F the Fresnel of the ior at the view (schlick),
    added to the surface's own light. Shadow rays pass it too, tinted, as
    through Limn's shadow maps' transmittance (at normal incidence there)."""
    share, ior, absorbed = glass
    fresnel = schlick(t, ior)
    tint = t.mix("MULTIPLY", 1.0, t.mix("MULTIPLY", 1.0, base, [share * a for a in absorbed], clamp=True),
                 t.math("SUBTRACT", 1.0, fresnel))
    return add(t, shader, t.node("ShaderNodeBsdfTransparent", Color=tint).outputs[0])


def map_material(mat, gm, mode):
    t = Tree(mat)
    principled = next((n for n in t.nodes if n.type == "BSDF_PRINCIPLED"), None)
    output = next((n for n in t.nodes if n.type == "OUTPUT_MATERIAL"), None)
    if principled is None or output is None:
        fail("material '%s'" % mat.name, "Blender's importer gave no Principled BSDF to map")
    inp = principled.inputs
    base = t.source(inp["Base Color"])
    normal = inp["Normal"].links[0].from_socket if inp["Normal"].is_linked else None
    glass = glass_of(gm)
    keep = 1.0 - glass[0] if glass else 1.0
    if mode == "phong":
        shader = build_phong(t, base, phong_values(gm), keep)
        em = gm.get("emissiveFactor", [0, 0, 0]) if gm else [0, 0, 0]
        if max(em) > 0.0 or (gm and "emissiveTexture" in gm):
            warn("phong emissive", "materials=phong: emissive materials are dark in Limn's Phong: left dark")
    else:
        shader = build_pbr(t, base, t.source(inp["Metallic"]), t.source(inp["Roughness"]), normal, keep)
        if inp["Emission"].is_linked or max(inp["Emission"].default_value[:3]) > 0.0:
            emission = t.node("ShaderNodeEmission", Color=t.source(inp["Emission"]),
                              Strength=t.source(inp["Emission Strength"]))
            shader = add(t, shader, emission.outputs[0])
    if glass:
        shader = add_glass(t, shader, base, glass)
        for link in list(output.inputs["Volume"].links):  # the importer's absorption: in the tint instead
            t.links.remove(link)
    alpha = inp["Alpha"]
    if alpha.is_linked or alpha.default_value < 1.0:
        mixed = t.node("ShaderNodeMixShader", Fac=t.source(alpha))
        t.links.new(t.node("ShaderNodeBsdfTransparent").outputs[0], mixed.inputs[1])
        t.links.new(shader, mixed.inputs[2])
        shader = mixed.outputs[0]
    for link in list(output.inputs["Surface"].links):
        t.links.remove(link)
    t.links.new(shader, output.inputs["Surface"])


def default_material(mode):
    """Limn's material for primitives without one."""
    mat = bpy.data.materials.new("limn_default")
    mat.use_nodes = True
    t = Tree(mat)
    output = next(n for n in t.nodes if n.type == "OUTPUT_MATERIAL")
    if mode == "phong":
        shader = build_phong(t, DEFAULT_PHONG["color"], DEFAULT_PHONG)
    else:  # Limn derives metallic 1 - k_d and the roughness of the exponent
        s = DEFAULT_PHONG["shininess"]
        shader = build_pbr(t, DEFAULT_PHONG["color"], 1.0 - DEFAULT_PHONG["kd"], (2.0 / (s + 2.0)) ** 0.25, None)
    for link in list(output.inputs["Surface"].links):
        t.links.remove(link)
    t.links.new(shader, output.inputs["Surface"])
    return mat


def linear_textures():
    """Colour textures as linear floats. Cycles filters an 8-bit sRGB image
    in sRGB and decodes after (an edge between texels of 60 and 230 comes out
    darker than either's light would mix); Limn's GL_SRGB8_ALPHA8 textures
    decode before filtering, as light mixes. A float copy of the decoded
    texels filters the same way in both."""
    copies = {}
    for mat in bpy.data.materials:
        if not mat.use_nodes:
            continue
        for node in mat.node_tree.nodes:
            image = getattr(node, "image", None) if node.type == "TEX_IMAGE" else None
            if image is None or image.is_float or image.colorspace_settings.name != "sRGB" or 0 in image.size:
                continue
            if image.name not in copies:
                w, h = image.size
                px = numpy.empty(w * h * 4, dtype=numpy.float32)
                image.pixels.foreach_get(px)  # the stored sRGB values over 255
                rgb = px.reshape(-1, 4)[:, :3]
                rgb[:] = numpy.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
                copy = bpy.data.images.new(image.name + "_linear", w, h, alpha=True, float_buffer=True)
                copy.colorspace_settings.name = "Linear"
                copy.alpha_mode = image.alpha_mode
                copy.pixels.foreach_set(px)
                copies[image.name] = copy
            node.image = copies[image.name]


def map_materials(doc, mode):
    linear_textures()
    gms = doc.get("materials", [])
    for mat in list(bpy.data.materials):
        m = re.match(r"limn_m(\d+)", mat.name)
        if m and mat.use_nodes and int(m.group(1)) < len(gms):
            map_material(mat, gms[int(m.group(1))], mode)
    fallback = None
    for obj in bpy.context.scene.objects:
        if obj.type != "MESH":
            continue
        slots = obj.material_slots
        if len(slots) == 0 or any(s.material is None for s in slots):
            fallback = fallback or default_material(mode)
            if len(slots) == 0:
                obj.data.materials.append(fallback)
            for s in slots:
                if s.material is None:
                    s.material = fallback


# ---------------------------------------------------------------- world


def map_world(spec):
    """sky.lua's sky as the world's Background: the gradient
    intensity * mix(horizon, zenith, clamp(d.y, 0, 1)) (engine/scene/sky.c),
    or the equirectangular map times intensity; plus the uniform ambient."""
    world = bpy.data.worlds.new("limn_world")
    bpy.context.scene.world = world
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    background = next(n for n in nodes if n.type == "BACKGROUND")
    background.inputs["Strength"].default_value = 1.0
    amb = spec["ambient"]
    sky = spec["sky"]
    if sky is None:
        background.inputs["Color"].default_value = (amb[0], amb[1], amb[2], 1.0)
        return
    k = sky["intensity"]
    if sky["map"]:
        try:
            image = bpy.data.images.load(sky["map"], check_existing=True)
            image.colorspace_settings.name = "Non-Color"  # radiance as stored, no transform
        except RuntimeError as e:
            fail("sky.map %s" % sky["map"], "Blender cannot read it: %s" % e)
        coords = nodes.new("ShaderNodeTexCoord")
        mapping = nodes.new("ShaderNodeMapping")
        # Limn's middle column looks along -Z (Blender's +Y); Blender's along +X.
        mapping.inputs["Rotation"].default_value = (0.0, 0.0, -math.pi / 2)
        env = nodes.new("ShaderNodeTexEnvironment")
        env.image, env.interpolation = image, "Linear"
        links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
        links.new(mapping.outputs["Vector"], env.inputs["Vector"])
        colour = env.outputs["Color"]
    else:
        coords = nodes.new("ShaderNodeTexCoord")
        split = nodes.new("ShaderNodeSeparateXYZ")
        links.new(coords.outputs["Generated"], split.inputs[0])
        ramp = nodes.new("ShaderNodeMixRGB")
        ramp.use_clamp = False
        clamp = nodes.new("ShaderNodeMath")
        clamp.operation, clamp.use_clamp = "MULTIPLY", True
        clamp.inputs[1].default_value = 1.0
        links.new(split.outputs["Z"], clamp.inputs[0])
        links.new(clamp.outputs[0], ramp.inputs["Fac"])
        ramp.inputs["Color1"].default_value = tuple(sky["horizon"]) + (1.0,)
        ramp.inputs["Color2"].default_value = tuple(sky["zenith"]) + (1.0,)
        colour = ramp.outputs[0]
    scaled = nodes.new("ShaderNodeMixRGB")
    scaled.blend_type = "MULTIPLY"
    scaled.inputs["Fac"].default_value = 1.0
    links.new(colour, scaled.inputs["Color1"])
    scaled.inputs["Color2"].default_value = (k, k, k, 1.0)
    plus = nodes.new("ShaderNodeMixRGB")
    plus.blend_type = "ADD"
    plus.inputs["Fac"].default_value = 1.0
    links.new(scaled.outputs[0], plus.inputs["Color1"])
    plus.inputs["Color2"].default_value = (amb[0], amb[1], amb[2], 1.0)
    links.new(plus.outputs[0], background.inputs["Color"])


# ---------------------------------------------------------------- camera, render


def set_camera(spec):
    scene = bpy.context.scene
    for obj in list(scene.objects):  # the spec's camera, not the file's
        if obj.type == "CAMERA":
            bpy.data.objects.remove(obj)
    cam = bpy.data.cameras.new("limn_camera")
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = math.radians(spec["fov_y"])
    d = math.dist(spec["eye"], spec["target"])
    cam.clip_start, cam.clip_end = max(d * 1e-5, 1e-6), d * 1e7
    obj = bpy.data.objects.new("limn_camera", cam)
    scene.collection.objects.link(obj)
    eye, target, up = (to_blender(spec[k]) for k in ("eye", "target", "up"))
    f = [t - e for t, e in zip(target, eye)]
    f = [x / norm(f) for x in f]
    r = cross(f, up)
    r = [x / norm(r) for x in r]
    u = cross(r, f)
    # The camera looks down its -Z with +Y up: columns r, u, -f.
    from mathutils import Matrix
    obj.matrix_world = Matrix(((r[0], u[0], -f[0], eye[0]), (r[1], u[1], -f[1], eye[1]),
                               (r[2], u[2], -f[2], eye[2]), (0, 0, 0, 1)))
    scene.camera = obj


def configure(spec):
    scene = bpy.context.scene
    # The importer keys glTF time t at frame t * fps: the pose at the spec's time, not Blender's frame 1.
    frame = spec["time"] * scene.render.fps / scene.render.fps_base
    scene.frame_set(math.floor(frame), subframe=frame - math.floor(frame))
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = spec["samples"]
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.seed = spec["seed"]
    c.use_animated_seed = False
    b = spec["bounces"]
    c.max_bounces = b
    c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = b
    c.volume_bounces = 0
    c.transparent_max_bounces = 64  # alpha cut-outs are not bounces
    c.blur_glossy = 0.0
    c.light_sampling_threshold = 0.0  # no light sample dropped at random
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0  # no clamping: unbiased
    c.caustics_reflective = c.caustics_refractive = True
    # Limn shades each pixel's centre once. Blender gives Cycles' box filter a width of 1 pixel
    # whatever filter_width says; a Gaussian takes the width: 0.01 (Blender's least) is the centre.
    c.pixel_filter_type = "GAUSSIAN"
    c.filter_width = 0.01
    c.film_exposure = 1.0
    scene.render.film_transparent = False
    scene.render.use_motion_blur = False
    scene.render.resolution_x, scene.render.resolution_y = spec["width"], spec["height"]
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_mode = "RGB"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    scene.render.use_file_extension = False


def render(spec, out):
    folder = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(folder):
        fail("output %s" % out, "no such folder")
    # Not created before Blender writes it (at the render's end): a render killed midway leaves nothing.
    tmp = os.path.join(folder, ".cycles-%s-%d.exr" % (os.path.basename(out), os.getpid()))
    try:
        bpy.context.scene.render.filepath = tmp
        bpy.ops.render.render(write_still=True)
        if not os.path.isfile(tmp) or os.path.getsize(tmp) == 0:
            fail("render", "Cycles wrote no image")
        os.replace(tmp, out)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def render_view(spec_path, out):
    global VIEW
    VIEW = "?"
    WARNED.clear()
    spec = read_spec(spec_path)
    with tempfile.TemporaryDirectory(prefix="limn-cycles-") as folder:
        doc, lights = import_scene(spec, folder)
        map_lights(lights)
        map_materials(doc, spec["materials"])
        map_world(spec)
        set_camera(spec)
        configure(spec)
        render(spec, out)


def main(argv):
    """Renders each SPEC OUT pair; 1 when any failed (each failure named, the others rendered)."""
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    if len(args) < 2 or len(args) % 2:
        print("%s: usage: blender -b --factory-startup -noaudio --python-exit-code 1 --python "
              "cli/cycles_render.py -- SPEC.json OUT.exr [SPEC.json OUT.exr ...]" % PREFIX, file=sys.stderr)
        return 1
    # limn reference's pipe: the pair's index once its OUT is complete (each view's time, and a view
    # known complete even when a later one kills Blender).
    progress = os.environ.get("LIMN_PROGRESS_FD")
    failed = 0
    for i in range(0, len(args), 2):  # several views in one run save Blender's start (seconds) a view
        try:
            render_view(args[i], args[i + 1])
            if progress:
                os.write(int(progress), b"%d\n" % (i // 2))
        except SpecError as e:
            print("%s: view '%s': %s" % (PREFIX, VIEW, e), file=sys.stderr)
            failed += 1
        except Exception as e:  # a fault of this script or of Blender's: still named by view
            print("%s: view '%s': %s: %s" % (PREFIX, VIEW, type(e).__name__, e), file=sys.stderr)
            failed += 1
    return 1 if failed else 0


if __name__ == "__main__":
    status = main(sys.argv)
    sys.stdout.flush()
    sys.stderr.flush()
    # The status at once; with 0 Blender quits as usual.
    if status:
        os._exit(status)
