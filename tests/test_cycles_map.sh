#!/usr/bin/env bash
# tools/cycles_render.py against Limn (docs/cycles.md): a white plane under a
# KHR sun, point and spot light, Cycles direct light (bounces 0) against
# `limn capture --tech dl` (ambient 0), mean brightness within 1% for each;
# two PBR spheres (a rough gold metal, a rough red dielectric) against
# materials=pbr, mean brightness within 1% and mean |difference| within 3% of
# the mean; a corrupt glTF and a bad spec fail naming the view and the part,
# exit 1, and leave no image. Linear EXR on both sides, compared by
# `limn compare` (mean |value| is the mean error against a black image).
# Skipped (77) without Blender.
set -u
limn=$1
root=$2
blender=${BLENDER:-blender}
command -v "$blender" >/dev/null ||
  { echo "test_cycles_map: skipped: no blender (Debian package blender: apt-get install blender)"; exit 77; }
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
tmp=$(mktemp -d /tmp/limn-cycles-map-XXXXXX)
trap 'rm -rf "$tmp"' EXIT
passed=0 failed=0
check() { # check NAME CONDITION...
  local name=$1; shift
  if "$@"; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL: $name"; fi
}
cycles() { # cycles SPEC OUT [SPEC OUT ...]: stderr in $tmp/err.txt, status in rc
  "$blender" -b --factory-startup -noaudio --python-exit-code 1 --python "$root/tools/cycles_render.py" -- "$@" \
    >"$tmp/log.txt" 2>"$tmp/err.txt"
  rc=$?
}
field() { # field JSON KEY: a number of limn compare --json
  python3 -c 'import json, sys; print(json.loads(sys.argv[1])[sys.argv[2]])' "$1" "$2"
}
mean() { field "$("$limn" compare "$1" "$tmp/black.exr" --json)" mean_error; }
within() { # within NAME VALUE LO HI
  python3 -c 'import sys; v, lo, hi = map(float, sys.argv[2:]); sys.exit(0 if lo <= v <= hi else 1)' "$@" ||
    { echo "  $1 = $2, wanted $3..$4"; return 1; }
}

python3 "$root/tests/cycles_map_scenes.py" "$tmp" 64 48 2 || exit 1
limn_dl() { # limn_dl SCENE OUT [SETS...]
  local scene=$1 out=$2; shift 2
  "$limn" capture --scene "$tmp/$scene.gltf" --tech dl --set ambient=0 --size 64x48 --quiet --output "$out" "$@" ||
    echo "  limn capture $scene failed"
}
limn_dl sun "$tmp/black.exr" --camera 1
for s in sun point spot; do limn_dl $s "$tmp/limn_$s.exr"; done
limn_dl spheres "$tmp/limn_spheres.exr" --set materials=pbr

cycles "$tmp/sun_phong.json" "$tmp/cycles_sun.exr" "$tmp/point_phong.json" "$tmp/cycles_point.exr" \
  "$tmp/spot_phong.json" "$tmp/cycles_spot.exr" "$tmp/spheres_pbr.json" "$tmp/cycles_spheres.exr"
check "cycles renders the four views" test "$rc" -eq 0 -a -f "$tmp/cycles_spheres.exr"
[ "$rc" -eq 0 ] || sed 's/^/  | /' "$tmp/err.txt" | tail -5
check "black is black" within "black mean" "$(mean "$tmp/black.exr")" 0 0
for s in sun point spot; do
  c=$(mean "$tmp/cycles_$s.exr") l=$(mean "$tmp/limn_$s.exr")
  ratio=$(python3 -c "print($c / $l if $l > 0 else 0)")
  echo "$s: Cycles direct mean $c, Limn dl $l, ratio $ratio"
  check "$s light: Cycles within 1% of dl" within "$s ratio" "$ratio" 0.99 1.01
done
c=$(mean "$tmp/cycles_spheres.exr") l=$(mean "$tmp/limn_spheres.exr")
d=$(field "$("$limn" compare "$tmp/cycles_spheres.exr" "$tmp/limn_spheres.exr" --json)" mean_error)
ratio=$(python3 -c "print($c / $l if $l > 0 else 0)") share=$(python3 -c "print($d / $l if $l > 0 else 1)")
echo "pbr spheres: Cycles mean $c, Limn pbr $l, ratio $ratio, mean |difference| $share of the mean"
check "pbr spheres: mean within 1%" within "pbr ratio" "$ratio" 0.99 1.01
check "pbr spheres: mean |difference| within 3% of the mean" within "pbr difference" "$share" 0 0.03

# sky.lua's sky as Cycles' world, against Limn's dl with the sky (its 3-band spherical harmonics):
# the gradient on a plane facing up; the map on the plane (up is up) and on a sphere filling the
# view, lit from +X by the map's bright patch (a map turned the wrong way lights the other side).
python3 - "$tmp" <<'PYEOF2' || exit 1
import json, sys
d = sys.argv[1]
grad = {"zenith": [0.1, 0.15, 0.3], "horizon": [0.3, 0.32, 0.35], "intensity": 2.0, "map": ""}
hdr = {"map": d + "/sky.hdr", "intensity": 1.0}
for scene, sky, name in (("sky", grad, "grad"), ("sky", hdr, "map"), ("skyball", hdr, "ballmap")):
    s = json.load(open("%s/%s_phong.json" % (d, scene)))
    s["samples"], s["sky"] = 64, sky  # the sky is sampled: 64 paths a pixel keep the noise near 1%
    json.dump(s, open("%s/%s.json" % (d, name), "w"))
PYEOF2
grad=(--set sky.enabled=true --set sky.zenith=0.1,0.15,0.3 --set sky.horizon=0.3,0.32,0.35 --set sky.intensity=2)
limn_dl sky "$tmp/limn_grad.exr" "${grad[@]}"
limn_dl sky "$tmp/limn_map.exr" --set sky.enabled=true --set "sky.map=$tmp/sky.hdr"
limn_dl skyball "$tmp/limn_ballmap.exr" --set sky.enabled=true --set "sky.map=$tmp/sky.hdr"
cycles "$tmp/grad.json" "$tmp/cycles_grad.exr" "$tmp/map.json" "$tmp/cycles_map.exr" \
  "$tmp/ballmap.json" "$tmp/cycles_ballmap.exr"
check "cycles renders the sky views" test "$rc" -eq 0 -a -f "$tmp/cycles_ballmap.exr"
[ "$rc" -eq 0 ] || sed 's/^/  | /' "$tmp/err.txt" | tail -5
for v in grad:0.98:1.02 map:0.95:1.05; do
  IFS=: read -r name lo hi <<<"$v"
  c=$(mean "$tmp/cycles_$name.exr") l=$(mean "$tmp/limn_$name.exr")
  ratio=$(python3 -c "print($c / $l if $l > 0 else 0)")
  echo "sky $name on a plane: Cycles mean $c, Limn dl $l, ratio $ratio"
  check "sky $name: plane within $lo..$hi of dl" within "sky $name ratio" "$ratio" "$lo" "$hi"
done
l=$(mean "$tmp/limn_ballmap.exr")
d=$(field "$("$limn" compare "$tmp/cycles_ballmap.exr" "$tmp/limn_ballmap.exr" --json)" mean_error)
share=$(python3 -c "print($d / $l if $l > 0 else 1)")
echo "sky map on a sphere: mean |difference| $share of Limn's mean"
check "sky map on a sphere: mean |difference| within 15%" within "sky map sphere difference" "$share" 0 0.15

# A corrupt glTF: named, exit 1, no image.
head -c 300 "$tmp/sun.gltf" >"$tmp/corrupt.gltf"
sed "s|$tmp/sun.gltf|$tmp/corrupt.gltf|; s|\"view\": \"sun\"|\"view\": \"broken\"|" "$tmp/sun_phong.json" \
  >"$tmp/corrupt.json"
cycles "$tmp/corrupt.json" "$tmp/corrupt.exr"
check "corrupt glTF: exit 1" test "$rc" -eq 1
check "corrupt glTF: named" grep -qF "limn cycles: view 'broken': scene $tmp/corrupt.gltf: not glTF JSON" "$tmp/err.txt"
check "corrupt glTF: no image" test ! -e "$tmp/corrupt.exr"
# A bad spec field, named; and a view after a good one that fails leaves the good one only.
sed 's|"samples": 2|"samples": -3|' "$tmp/point_phong.json" >"$tmp/bad.json"
cycles "$tmp/sun_phong.json" "$tmp/good.exr" "$tmp/bad.json" "$tmp/bad.exr"
check "bad spec: exit 1" test "$rc" -eq 1
check "bad spec: named" grep -qF "limn cycles: view 'point': samples: wants an integer in 1..1048576, not -3" "$tmp/err.txt"
check "bad spec: no image, the good view's image" test ! -e "$tmp/bad.exr" -a -s "$tmp/good.exr"
check "no temporary file left" test -z "$(find "$tmp" -name '.cycles-*')"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
