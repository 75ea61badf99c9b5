#!/usr/bin/env python3
"""Writes the scenes of tests/test_cycles_map.sh into DIR: for each, a .gltf
(buffers as data URIs) with one camera, and the Cycles spec of that camera
(cli/cycles_render.py), NAME_phong.json and NAME_pbr.json, direct light only.

    cycles_map_scenes.py DIR WIDTH HEIGHT SAMPLES

  sun, point, spot  an 8 x 8 white plane (base 0.8, metallic 0, roughness 0:
                    Limn's Phong gives it k_s 0.04 at exponent 1024, a lobe
                    whose highlight each light puts outside the view) under
                    one light of each KHR_lights_punctual type, placed behind
                    the camera; engine powers 1, 2 and 4 (candela or lux times
                    683 pi)
  range             the point light with range 6: its window clamp(1 -
                    (d/6)^4, 0, 1) runs from about 0.5 at the view's centre
                    to 0 before its far edge
  sky, skyball      a white plane and a white sphere lit by no light (a spot
                    aimed at nothing), for sky.lua's gradient and map; sky.hdr,
                    the map (write_map)
  checker           the white plane textured with a 4x4 checker of sRGB 60
                    and 230 (checker.png, each texel a metre: magnified, so
                    the filter blends neighbouring texels across the view)
                    under the sun
  spheres           a rough gold metal and a rough red dielectric sphere under
                    a sun, for materials=pbr (one light: Cycles, which picks one
                    light a sample, is then free of noise)
Standard library only."""
import base64
import json
import math
import os
import struct
import sys
import zlib

PHOTOMETRIC = 683.0 * math.pi  # glTF cd or lux per engine unit (engine/scene/gltf.h)


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def normalize(a):
    n = math.sqrt(sum(x * x for x in a))
    return [x / n for x in a]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def quat_of_basis(r, u, b):
    """Unit quaternion (x, y, z, w) of the rotation whose columns are r, u, b."""
    m = [[r[0], u[0], b[0]], [r[1], u[1], b[1]], [r[2], u[2], b[2]]]
    t = m[0][0] + m[1][1] + m[2][2]
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        return [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s]
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(1.0 + m[i][i] - m[j][j] - m[k][k]) * 2
    q = [0.0] * 4
    q[i] = 0.25 * s
    q[j] = (m[j][i] + m[i][j]) / s
    q[k] = (m[k][i] + m[i][k]) / s
    q[3] = (m[k][j] - m[j][k]) / s
    return q


def look(eye, target, up=(0.0, 1.0, 0.0)):
    """A node's rotation looking from eye at target (its -Z forward, +Y up)."""
    f = normalize(sub(target, eye))
    r = normalize(cross(f, up))
    u = cross(r, f)
    return quat_of_basis(r, u, [-x for x in f])


class Gltf:
    def __init__(self):
        self.doc = {"asset": {"version": "2.0", "generator": "limn tests/cycles_map_scenes.py"},
                    "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [], "materials": [],
                    "accessors": [], "bufferViews": [], "buffers": []}
        self.data = bytearray()

    def node(self, **kw):
        self.doc["nodes"].append(kw)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def view(self, floats, kind, target):
        offset = len(self.data)
        self.data += struct.pack("<%d%s" % (len(floats), "f" if kind == 5126 else "I"), *floats)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": offset, "byteLength": len(self.data) - offset,
                                        "target": target})
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, values, type_, width):
        kind = 5126 if type_ != "SCALAR" else 5125
        acc = {"bufferView": self.view(values, kind, 34962 if kind == 5126 else 34963), "componentType": kind,
               "count": len(values) // width, "type": type_}
        if type_ == "VEC3" and width == 3:
            acc["min"] = [min(values[i::3]) for i in range(3)]
            acc["max"] = [max(values[i::3]) for i in range(3)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def mesh(self, positions, normals, indices, material, uvs=None):
        prim = {"attributes": {"POSITION": self.accessor(positions, "VEC3", 3),
                               "NORMAL": self.accessor(normals, "VEC3", 3)},
                "indices": self.accessor(indices, "SCALAR", 1), "material": material}
        if uvs:
            prim["attributes"]["TEXCOORD_0"] = self.accessor(uvs, "VEC2", 2)
        self.doc["meshes"].append({"primitives": [prim]})
        return len(self.doc["meshes"]) - 1

    def material(self, name, base, metallic, roughness):
        self.doc["materials"].append({"name": name, "pbrMetallicRoughness": {
            "baseColorFactor": base + [1.0], "metallicFactor": metallic, "roughnessFactor": roughness}})
        return len(self.doc["materials"]) - 1

    def texture(self, material, png):
        """PNG bytes as the material's base colour texture (a data URI)."""
        self.doc.setdefault("images", []).append({"uri": "data:image/png;base64," + base64.b64encode(png).decode()})
        self.doc.setdefault("textures", []).append({"source": len(self.doc["images"]) - 1})
        self.doc["materials"][material]["pbrMetallicRoughness"]["baseColorTexture"] = {
            "index": len(self.doc["textures"]) - 1}

    def light(self, light, eye, target=None):
        ext = self.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})
        ext["lights"].append(light)
        self.doc.setdefault("extensionsUsed", ["KHR_lights_punctual"])
        node = {"name": light["type"], "translation": eye,
                "extensions": {"KHR_lights_punctual": {"light": len(ext["lights"]) - 1}}}
        if target is not None:
            node["rotation"] = look(eye, target, (0.0, 0.0, -1.0) if abs(target[0] - eye[0]) + abs(
                target[2] - eye[2]) < 1e-9 else (0.0, 1.0, 0.0))
        self.node(**node)

    def camera(self, eye, target, fov_y):
        cams = self.doc.setdefault("cameras", [])
        cams.append({"type": "perspective", "perspective": {"yfov": math.radians(fov_y), "znear": 0.05,
                                                            "zfar": 100.0}})
        self.node(name="camera", camera=len(cams) - 1, translation=eye, rotation=look(eye, target))
        return {"eye": eye, "target": target, "up": [0.0, 1.0, 0.0], "fov_y": fov_y}

    def write(self, path):
        self.doc["buffers"] = [{"byteLength": len(self.data),
                                "uri": "data:application/octet-stream;base64," + base64.b64encode(self.data).decode()}]
        with open(path, "w") as f:
            json.dump(self.doc, f)


def plane(g, material, half=4.0, uv=None):
    p = [-half, 0, -half, half, 0, -half, half, 0, half, -half, 0, half]
    uvs = [0, 0, uv, 0, uv, uv, 0, uv] if uv else None
    g.node(name="plane", mesh=g.mesh(p, [0, 1, 0] * 4, [0, 2, 1, 0, 3, 2], material, uvs))


def checker_png(n=4, dark=60, light=230):
    """An n x n RGB PNG of alternating sRGB grey texels (zlib: standard library)."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    rows = b"".join(b"\0" + bytes(v for x in range(n) for v in [dark if (x + y) % 2 else light] * 3)
                    for y in range(n))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", n, n, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def sphere(g, centre, radius, material, rings=24, segments=48):
    pos, nrm, idx = [], [], []
    for i in range(rings + 1):
        th = math.pi * i / rings
        for j in range(segments + 1):
            ph = 2 * math.pi * j / segments
            n = [math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph)]
            nrm += n
            pos += [c + radius * x for c, x in zip(centre, n)]
    for i in range(rings):
        for j in range(segments):
            a, b = i * (segments + 1) + j, (i + 1) * (segments + 1) + j
            idx += [a, a + 1, b, a + 1, b + 1, b]
    g.node(name="sphere", mesh=g.mesh(pos, nrm, idx, material))


def write_map(path, width=64, height=32):
    """An equirectangular Radiance RGBE map (flat scanlines): a dim blue sky
    (0.05, 0.08, 0.12) over dark ground (0.02), and a bright warm patch
    (3, 2.5, 2) around the column looking along +X (3/4 of the width), 30
    degrees up: a sphere lit by it shows which way the map is turned."""
    def rgbe(c):
        m = max(c)
        if m < 1e-32:
            return bytes(4)
        e = math.frexp(m)[1]
        return bytes([int(x / 2.0 ** e * 256) for x in c] + [e + 128])
    rows = []
    for r in range(height):
        elevation = 90.0 - 180.0 * (r + 0.5) / height
        for c in range(width):
            azimuth = 360.0 * ((c + 0.5) / width - 0.75)  # 0 at +X
            if abs(azimuth) < 25.0 and abs(elevation - 30.0) < 20.0:
                rows.append(rgbe((3.0, 2.5, 2.0)))
            else:
                rows.append(rgbe((0.05, 0.08, 0.12) if elevation > 0 else (0.02, 0.02, 0.02)))
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (height, width))
        f.write(b"".join(rows))


def main(folder, width, height, samples):
    eye, target = [0.0, 3.0, 3.0], [0.0, 0.0, 0.0]
    lights = {
        "sun": ({"type": "directional", "intensity": PHOTOMETRIC}, [0.0, 5.0, 5.0], [0.0, 0.0, 0.0]),
        "point": ({"type": "point", "intensity": 2 * PHOTOMETRIC}, [1.0, 3.5, 3.5], None),
        "range": ({"type": "point", "intensity": 2 * PHOTOMETRIC, "range": 6.0}, [1.0, 3.5, 3.5], None),
        "spot": ({"type": "spot", "intensity": 4 * PHOTOMETRIC,
                  "spot": {"innerConeAngle": 0.15, "outerConeAngle": 0.35}}, [0.0, 4.0, 4.0], [0.0, 0.0, 0.5]),
    }
    specs = {}
    for name, (light, at, aim) in lights.items():
        g = Gltf()
        plane(g, g.material("white", [0.8, 0.8, 0.8], 0.0, 0.0))
        g.light(light, at, aim)
        specs[name] = (g, g.camera(eye, target, 40.0))
        g.camera(eye, [0.0, 6.0, 9.0], 40.0)  # camera 1 sees nothing: Limn's black image
    g = Gltf()
    plane(g, g.material("checker", [1.0, 1.0, 1.0], 0.0, 0.0), uv=2.0)
    g.texture(0, checker_png())
    g.light(*lights["sun"][:2], lights["sun"][2])
    specs["checker"] = (g, g.camera(eye, target, 40.0))
    g = Gltf()
    sphere(g, [-0.6, 0.5, 0.0], 0.5, g.material("gold", [1.0, 0.77, 0.34], 1.0, 0.35))
    sphere(g, [0.6, 0.5, 0.0], 0.5, g.material("red", [0.7, 0.1, 0.1], 0.0, 0.6))
    g.light({"type": "directional", "intensity": 2 * PHOTOMETRIC}, [-2.0, 3.0, 2.0], [0.0, 0.5, 0.0])
    specs["spheres"] = (g, g.camera([0.0, 0.8, 3.0], [0.0, 0.5, 0.0], 35.0))
    # Lit by the sky alone: a spot aimed up, at nothing, stands in for Limn's default light.
    away = ({"type": "spot", "intensity": 1.0, "spot": {"outerConeAngle": 0.1}}, [0.0, 20.0, 0.0], [0.0, 30.0, 0.0])
    g = Gltf()
    plane(g, g.material("white", [0.8, 0.8, 0.8], 0.0, 0.0))
    g.light(*away)
    specs["sky"] = (g, g.camera(eye, target, 40.0))
    g = Gltf()
    sphere(g, [0.0, 0.0, 0.0], 0.5, g.material("white", [0.8, 0.8, 0.8], 0.0, 0.0))
    g.light(*away)
    specs["skyball"] = (g, g.camera([0.0, 0.0, 1.2], [0.0, 0.0, 0.0], 35.0))  # the sphere fills the view
    write_map(os.path.join(folder, "sky.hdr"))
    for name, (g, cam) in specs.items():
        path = os.path.join(folder, name + ".gltf")
        g.write(path)
        for materials in ("phong", "pbr"):
            with open(os.path.join(folder, "%s_%s.json" % (name, materials)), "w") as f:
                json.dump({"scene": os.path.abspath(path), "camera": cam, "view": name, "width": width,
                           "height": height, "samples": samples, "bounces": 0, "seed": 1,
                           "materials": materials, "sky": None}, f)


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]))
