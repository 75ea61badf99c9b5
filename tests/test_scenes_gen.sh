#!/usr/bin/env bash
# data/scenes is what data/gen_scenes.c writes, byte for byte: regenerate
# into a scratch folder and compare every file (the reference set's scenes
# under reference/ included).
set -euo pipefail
gen=$1 root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$gen" "$tmp" >/dev/null
n=0
while IFS= read -r f; do
  cmp "$tmp/$f" "$root/data/scenes/$f" || { echo "FAIL: $f differs from the checked-in copy"; exit 1; }
  n=$((n + 1))
done < <(cd "$tmp" && find . -type f | sort)
[ "$n" -ge 24 ] || { echo "FAIL: only $n files generated"; exit 1; }
total=$(du -sb "$root"/data/scenes | cut -f1)
[ "$total" -lt 15000000 ] || { echo "FAIL: data/scenes is $total bytes"; exit 1; }
echo "ok: $n files reproduce, $total bytes"

# The scenes that move: their animations, channels, key ranges and skin, read
# from the GLB's JSON and binary chunks (the loader's own checks are in
# tests/test_view.c and the animation tests).
command -v python3 >/dev/null || { echo "FAIL: the animation checks need python3 (Debian python3)"; exit 1; }
python3 - "$root/data/scenes" <<'PY'
import json, math, struct, sys

def glb(path):
    b = open(path, "rb").read()
    n = struct.unpack_from("<I", b, 12)[0]
    doc = json.loads(b[20:20 + n])
    return doc, b[20 + n + 8:]

def floats(doc, binary, acc):
    a = doc["accessors"][acc]
    v = doc["bufferViews"][a["bufferView"]]
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4, "MAT4": 16}[a["type"]]
    return struct.unpack_from("<%df" % (a["count"] * width), binary, v.get("byteOffset", 0)), width

def near(a, b, eps=1e-5):
    return all(abs(x - y) <= eps for x, y in zip(a, b))

def quat(axis, deg):
    h = math.radians(deg) / 2
    return [c * math.sin(h) for c in axis] + [math.cos(h)]

fails = []
def check(ok, what):
    if not ok: fails.append(what)

# scene: animation, target node, path, interpolation, keys, first and last time, last value
want = {
    "turntable": ("orbit", "pivot", "rotation", "LINEAR", 5, 0, 4, quat((0, 1, 0), 360)),
    "door": ("open", "hinge", "rotation", "CUBICSPLINE", 2, 0.5, 1.5, quat((0, 1, 0), 90)),
    "bending_tube": ("bend", "bend", "rotation", "LINEAR", 3, 0, 2, quat((0, 0, 1), 90)),
    "moving_light": ("cross", "lamp", "translation", "LINEAR", 2, 0, 3, [1.5, 2, 0]),
}
for scene, (name, node, path, interp, keys, t0, t1, last) in want.items():
    doc, binary = glb("%s/%s.glb" % (sys.argv[1], scene))
    anims = doc.get("animations", [])
    check(len(anims) == 1 and anims[0]["name"] == name, "%s: one animation '%s'" % (scene, name))
    if not anims: continue
    a = anims[0]
    check(len(a["channels"]) == 1 and len(a["samplers"]) == 1, "%s: one channel" % scene)
    ch = a["channels"][0]
    sm = a["samplers"][ch["sampler"]]
    nodes = doc["nodes"]
    check(nodes[ch["target"]["node"]]["name"] == node and ch["target"]["path"] == path,
          "%s: the channel moves %s.%s" % (scene, node, path))
    check(sm["interpolation"] == interp, "%s: %s keys" % (scene, interp))
    times, _ = floats(doc, binary, sm["input"])
    values, width = floats(doc, binary, sm["output"])
    per_key = 3 if interp == "CUBICSPLINE" else 1
    check(len(times) == keys and all(b > a for a, b in zip(times, times[1:])), "%s: %d increasing keys" % (scene, keys))
    check(times[0] == t0 and times[-1] == t1, "%s: keys from %g to %g s" % (scene, t0, t1))
    acc = doc["accessors"][sm["input"]]
    check(acc["min"] == [t0] and acc["max"] == [t1], "%s: the input's min and max" % scene)
    check(len(values) == keys * per_key * width, "%s: %d values a key" % (scene, per_key))
    value = values[(keys * per_key - (2 if per_key == 3 else 1)) * width:][:width]
    check(near(value, last), "%s: the last key is %s, not %s" % (scene, last, value))
    if path == "rotation":
        for k in range(keys):
            q = values[(k * per_key + (1 if per_key == 3 else 0)) * width:][:4]
            check(abs(math.sqrt(sum(c * c for c in q)) - 1) < 1e-6, "%s: key %d is a unit quaternion" % (scene, k))

# The turntable's first camera rides the pivot; the door hangs on its hinge.
doc, _ = glb(sys.argv[1] + "/turntable.glb")
cam = [n for n in doc["nodes"] if n.get("camera") == 0][0]
check(cam["name"] == "orbit" and doc["nodes"].index(cam) in doc["nodes"][[n["name"] for n in doc["nodes"]].index("pivot")]["children"],
      "turntable: camera 0 is the pivot's child")
doc, _ = glb(sys.argv[1] + "/door.glb")
hinge = [n for n in doc["nodes"] if n["name"] == "hinge"][0]
check([doc["nodes"][c]["name"] for c in hinge.get("children", [])] == ["door"], "door: the door hangs on the hinge")
check(any(l["type"] == "directional" for l in doc["extensions"]["KHR_lights_punctual"]["lights"]), "door: a sun")

# The tube's skin: two joints, every vertex's weights sum to 1, the bend blends.
doc, binary = glb(sys.argv[1] + "/bending_tube.glb")
skins = doc.get("skins", [])
check(len(skins) == 1 and [doc["nodes"][j]["name"] for j in skins[0]["joints"]] == ["base", "bend"], "tube: joints base, bend")
tube = [n for n in doc["nodes"] if n["name"] == "tube"][0]
check(tube.get("skin") == 0, "tube: the node has the skin")
prim = doc["meshes"][tube["mesh"]]["primitives"][0]
weights, _ = floats(doc, binary, prim["attributes"]["WEIGHTS_0"])
n = len(weights) // 4
check(n > 200 and all(abs(sum(weights[i * 4:i * 4 + 4]) - 1) < 1e-6 for i in range(n)), "tube: weights sum to 1")
check(sum(1 for i in range(n) if 0 < weights[i * 4 + 1] < 1) >= 2 * 17, "tube: two rings or more blend the joints")
check(doc["accessors"][prim["indices"]]["count"] // 3 < 1000, "tube: a few hundred triangles")
ibm, _ = floats(doc, binary, skins[0]["inverseBindMatrices"])
check(near(ibm[16 + 12:16 + 15], [0, -1, 0]), "tube: bend's inverse bind matrix undoes its height 1")

# The big scene (benchmarks) and its small size (tests): triangles drawn over
# every mesh node (instances counted), nodes, shared meshes, lights, views;
# the instanced form places the same spheres (translation, yaw, scale) as
# the one of a node each.
def big_stats(path):
    doc, binary = glb(path)
    nodes, meshes = doc["nodes"], doc["meshes"]
    tris = 0
    places = []
    for n in nodes:
        if "mesh" not in n: continue
        per = sum(doc["accessors"][p["indices"]]["count"] // 3 for p in meshes[n["mesh"]]["primitives"])
        inst = n.get("extensions", {}).get("EXT_mesh_gpu_instancing")
        if inst:
            t, _ = floats(doc, binary, inst["attributes"]["TRANSLATION"])
            r, _ = floats(doc, binary, inst["attributes"]["ROTATION"])
            s, _ = floats(doc, binary, inst["attributes"]["SCALE"])
            for i in range(len(t) // 3):
                places.append((n["mesh"], t[i * 3:i * 3 + 3], r[i * 4:i * 4 + 4], s[i * 3:i * 3 + 3]))
            tris += per * (len(t) // 3)
        else:
            if n["name"].startswith("ball"):
                places.append((n["mesh"], n["translation"], n["rotation"], n["scale"]))
            tris += per
    lights = doc["extensions"]["KHR_lights_punctual"]["lights"]
    return doc, tris, places, lights

d = sys.argv[1] + "/big/"
doc, tris, places, lights = big_stats(d + "big.glb")
check(tris >= 1500000, "big: %d triangles drawn, want 1.5 M or more" % tris)
check(len(doc["nodes"]) >= 400 and len(places) == 400, "big: 400 spheres, hundreds of nodes")
check(len(doc["meshes"]) <= 5, "big: the spheres share a few meshes")
check([l["type"] for l in lights].count("directional") == 1 and [l["type"] for l in lights].count("point") == 8,
      "big: a sun and eight point lights")
check(len([l for l in open(d + "big.cams") if not l.startswith("#")]) == 3, "big: three views in big.cams")
doc, small_tris, small_places, lights = big_stats(d + "big_small.glb")
check(10000 < small_tris < 40000 and len(small_places) == 64 and len(lights) == 9,
      "big_small: 64 spheres, tens of thousands of triangles (%d), the same lights" % small_tris)
doc, inst_tris, inst_places, _ = big_stats(d + "big_small_instanced.glb")
check("EXT_mesh_gpu_instancing" in doc.get("extensionsRequired", []), "big_small_instanced: requires the extension")
check(inst_tris == small_tris and len(doc["nodes"]) < 20, "big_small_instanced: the same triangles from a node a mesh")
check(len(inst_places) == len(small_places) and
      all(any(p[0] == q[0] and near(p[1], q[1], 1e-4) and near(p[2], q[2], 1e-4) and near(p[3], q[3], 1e-4)
              for q in small_places)
          for p in inst_places), "big_small_instanced: each instance is a sphere of big_small")

if fails:
    print("FAIL: " + "\nFAIL: ".join(fails))
    sys.exit(1)
print("ok: turntable, door, bending_tube and moving_light have their animations and skin; big has %d triangles" % tris)
PY
