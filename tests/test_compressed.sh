#!/usr/bin/env bash
# Corrupt copies of the compressed test scenes (tests/compressed) are refused
# naming the mesh and primitive, with exit 2 and no output: each copy with
# its mesh 0 primitive 0 data broken (python3 writes them from the checked-in
# files): a Draco stream cut short and one with its header overwritten, a
# meshopt stream whose header byte is wrong and one cut short, a quantized
# POSITION view shorter than its accessor.
set -euo pipefail
limn=$1 dir=$2
command -v python3 >/dev/null || { echo "SKIP: needs python3 (Debian python3)"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
python3 - "$dir" "$tmp" <<'PY'
import json, struct, sys
src, out = sys.argv[1:]

def read(name):
    b = open("%s/%s.glb" % (src, name), "rb").read()
    n = struct.unpack_from("<I", b, 12)[0]
    return json.loads(b[20:20 + n]), bytearray(b[20 + n + 8:])

def write(name, doc, binary):
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(binary), b"BIN\0") + binary
    open("%s/%s.glb" % (out, name), "wb").write(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)

prim = lambda doc: doc["meshes"][0]["primitives"][0]

doc, b = read("primitives_draco")
view = doc["bufferViews"][prim(doc)["extensions"]["KHR_draco_mesh_compression"]["bufferView"]]
cut = json.loads(json.dumps(doc))
cut["bufferViews"][prim(doc)["extensions"]["KHR_draco_mesh_compression"]["bufferView"]]["byteLength"] = 12
write("draco_cut", cut, bytearray(b))
at = view.get("byteOffset", 0)
bad = bytearray(b)
bad[at:at + 5] = b"XXXXX"  # the DRACO magic
write("draco_header", doc, bad)

doc, b = read("primitives_meshopt")
ext = doc["bufferViews"][doc["accessors"][prim(doc)["attributes"]["POSITION"]]["bufferView"]]["extensions"]["EXT_meshopt_compression"]
bad = bytearray(b)
bad[ext.get("byteOffset", 0)] = 0x00  # the header byte, 0xa0 for vertex data
write("meshopt_header", doc, bad)
ext["byteLength"] = 8
write("meshopt_cut", doc, bytearray(b))

doc, b = read("primitives_quantized")
acc = doc["accessors"][prim(doc)["attributes"]["POSITION"]]
doc["bufferViews"][acc["bufferView"]]["byteLength"] = 4
write("quantized_cut", doc, b)
PY
fails=0
expect() { # name, what the message must name besides the mesh and primitive
  local f=$tmp/$1.glb out=$tmp/$1.out.glb rc=0
  "$limn" export-gltf --scene "$f" --output "$out" 2>"$tmp/err" >/dev/null || rc=$?
  if [ "$rc" -ne 2 ] || ! grep -q "$f: mesh 0 primitive 0: " "$tmp/err" || ! grep -q "$2" "$tmp/err" || [ -e "$out" ]; then
    echo "FAIL: $1: exit $rc, want 2 naming mesh 0 primitive 0 and '$2' and no output: $(cat "$tmp/err")"
    fails=$((fails + 1))
  else
    echo "ok: $1: $(tail -1 "$tmp/err")"
  fi
}
expect draco_cut KHR_draco_mesh_compression
expect draco_header KHR_draco_mesh_compression
expect meshopt_header EXT_meshopt_compression
expect meshopt_cut EXT_meshopt_compression
expect quantized_cut "POSITION: accessor"
[ "$fails" -eq 0 ]
