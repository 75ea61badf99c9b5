#!/usr/bin/env bash
# The Khronos glTF validator finds no error in a glTF file the project writes:
# the test scenes as data/gen_scenes.c writes them (test_scenes_gen holds the
# checked-in copies to those bytes) and `limn export-gltf` outputs, .glb and
# .gltf with textures beside. Skips (77) without node or the validator
# package (npm install --prefix tools/gltf_validator; .ci/run installs it).
set -euo pipefail
limn=$1 gen=$2 root=$3
command -v node >/dev/null || { echo "SKIP: needs node (Debian nodejs) for the glTF validator"; exit 77; }
[ -d "$root/tools/gltf_validator/node_modules/gltf-validator" ] ||
  { echo "SKIP: gltf-validator is not installed: npm install --prefix tools/gltf_validator"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/scenes" "$tmp/export"
"$gen" "$tmp/scenes" >/dev/null
export LIMN_ROOT=$root
for s in cornell "$root"/data/scenes/{primitives,office,night}.glb "$root/data/scenes/big/big_small_instanced.glb"; do
  "$limn" export-gltf --scene "$s" --output "$tmp/export/$(basename "$s" .glb).glb"
done
"$limn" export-gltf --scene "$root/data/scenes/primitives.glb" --output "$tmp/export/primitives_text.gltf"
"$limn" export-gltf --scene "$root/data/scenes/door.glb" --time 1.5 --output "$tmp/export/door.glb"
files="$(find "$tmp/scenes" "$tmp/export" -name '*.glb' -o -name '*.gltf' | sort) $root/data/scenes/pov_ball.gltf"
n=$(echo $files | wc -w)
[ "$n" -ge 20 ] || { echo "FAIL: only $n glTF files written"; exit 1; }
# shellcheck disable=SC2086
node "$root/tools/gltf_validator/validate.js" $files | sed "s|$tmp/||"
echo "ok: $n files, no validator error"
