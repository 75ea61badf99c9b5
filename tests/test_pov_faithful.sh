#!/usr/bin/env bash
# Faithfulness of the POV-Ray export: with indirect light off on both sides
# (POV-Ray without radiosity, the engine's `dl` with ambient 0) and no
# shadows on either (the engine's direct light has no shadow maps yet), the
# engine's image of cornell_pov and of data/scenes/pov_ball.gltf must match
# POV-Ray's. What is left in a GI
# comparison is then the GI's own error. Also: the radiosity export renders.
# Skipped (77) where povray is not installed (tools/dev.sh installs it).
set -u
limn=$1
root=$2
. "$(dirname "$0")/shell_test.sh"
needs povray "tools/dev.sh installs it"
scratch pov
size=128x96 w=128 h=96

num() { grep -o "\"$1\": [-0-9.e+]*" "$tmp/m.json" | awk '{print $2}'; }

# faithful SCENE NAME BOUND [MATERIALS]: export, render both, compare, bound the mean error.
faithful() {
  local scene=$1 name=$2 bound=$3 materials=${4:-phong}
  "$limn" export-pov --scene "$scene" --size $size --radiosity off --shadows off --materials $materials \
    --output "$tmp/$name.pov" 2>"$tmp/export.err" || { cat "$tmp/export.err"; fail "export-pov $name"; }
  # Run where the files are: POV-Ray writes only under permitted directories.
  (cd "$tmp" && povray -D -V +I$name.pov +O$name-pov.exr +FE +W$w +H$h -A >"$tmp/pov.log" 2>&1) \
    || { sed 's/^/  | /' "$tmp/pov.log" | tail -20; fail "povray could not render the export of $name"; }
  "$limn" capture --scene "$scene" --script scripts/pp.lua --tech dl --set ambient=0 --set materials=$materials --size $size \
    --output "$tmp/$name-engine.exr" --quiet || fail "capture $name"
  "$limn" compare "$tmp/$name-engine.exr" "$tmp/$name-pov.exr" --json >"$tmp/m.json" || fail "compare $name"
  cat "$tmp/m.json"
  local mean pearson
  mean=$(num mean_error) pearson=$(num pearson)
  echo "$name: engine dl against POV-Ray (no radiosity, no shadows) at $size: mean error $mean, Pearson $pearson"
  awk -v m="$mean" -v b="$bound" 'BEGIN { exit !(m < b) }' || fail "$name: mean error $mean is not below $bound"
  awk -v p="$pearson" 'BEGIN { exit !(p > 0.999) }' || fail "$name: Pearson $pearson is not above 0.999"
}

# The Cornell box lit by an inverse-square point light, a parallel light and
# a spot. Measured 0.00195 (the image's mean value is about 0.5). Nearly all
# of it is 54 pixels whose centres lie exactly on the edges where the left
# wall meets ceiling and floor (the box is symmetric and the view 4:3): a tie
# that GL's rasterizer gives to the ceiling and POV-Ray to the wall. Elsewhere
# the two agree to about 0.1% (the G-buffer's 8-bit albedo, 16-bit light).
faithful cornell_pov cornell 0.005
# The built-in box with its one inverse-square light. Measured 0.0010.
faithful cornell cornell1 0.005
# A glTF file: parented, rotated and non-uniformly scaled nodes (normals by
# the inverse transpose), smooth normals, a rotated camera with its own fov,
# a parallel light, Phong from metallic-roughness. Measured 0.0007.
faithful "$root/data/scenes/pov_ball.gltf" ball 0.003
# The same file through the pbr technique against POV-Ray's closest finish
# (pov.h: Blinn specular for GGX, no Fresnel rise): close, not exact, and the
# export says so. Measured 0.016.
faithful "$root/data/scenes/pov_ball.gltf" ball_pbr 0.03 pbr
grep -q "metallic-roughness written as POV-Ray's closest finish" "$tmp/export.err" || fail "the pbr export does not say it approximates"

# glTF point and spot lights (KHR_lights_punctual: 1/d^2, candela through the
# exposure) at several heights over a floor, without range and with ranges far
# enough that the window is 1 to within 1/512 over the scene; the intensity
# grows with the height squared so the floor stays about as bright. A range
# ending inside the scene is refused by name. Measured at most 0.0004 (Pearson 0.9999999).
for view in 0.5: 0.5:40 1.5:100 3: 3:40; do
  y=${view%%:*} range=${view#*:}
  intensity=$(awk -v h=$y 'BEGIN { printf "%.6g", 1.5 * h * h * 683 * 3.14159265 }')
  name=lights_h${y/./_}_r${range:-none}
  sed -e "s/@H@/$y/g" -e "s/@I@/$intensity/g" -e "s/@RANGE@/${range:+, \"range\": $range}/g" \
    "$root/tests/pov_lights.gltf.in" >"$tmp/$name.gltf"
  faithful "$tmp/$name.gltf" "$name" 0.003
done
sed -e "s/@H@/1.5/g" -e "s/@I@/5000/g" -e 's/@RANGE@/, "range": 4/g' "$root/tests/pov_lights.gltf.in" >"$tmp/near.gltf"
"$limn" export-pov --scene "$tmp/near.gltf" --size $size --output "$tmp/near.pov" 2>"$tmp/near.err" \
  && fail "a range ending inside the scene was exported"
grep -q "light 'bulb': range 4: the KHR_lights_punctual window" "$tmp/near.err" || { cat "$tmp/near.err"; fail "the refusal does not name the light"; }

# Ray-traced reflections against POV-Ray's reflection of the same finish: the
# left wall of cornell_mirror is a perfect mirror (reflection 1, no diffuse).
# Measured at 128x96: rays at full size 0.0017, at half size (the default,
# edges upsampled) 0.0094; without reflections the mirror is black: 0.069.
mirror() {
  local scale=$1 bound=$2
  "$limn" capture --scene cornell_mirror --script scripts/pp.lua --tech dl --set ambient=0 \
    --set reflections.enabled=true --set reflections.scale=$scale --size $size \
    --output "$tmp/mirror-$scale.exr" --quiet || fail "capture mirror at scale $scale"
  "$limn" compare "$tmp/mirror-$scale.exr" "$tmp/mirror-pov.exr" --json >"$tmp/m.json" || fail "compare mirror"
  local mean
  mean=$(num mean_error)
  echo "mirror: engine reflections at scale $scale against POV-Ray at $size: mean error $mean (bound $bound)"
  awk -v m="$mean" -v b="$bound" 'BEGIN { exit !(m < b) }' || fail "mirror at scale $scale: mean error $mean is not below $bound"
}
"$limn" export-pov --scene cornell_mirror --size $size --radiosity off --shadows off --output "$tmp/mirror.pov" \
  || fail "export-pov mirror"
grep -q "reflection 1 }" "$tmp/mirror.pov" || fail "the mirror's finish has no reflection"
(cd "$tmp" && povray -D -V +Imirror.pov +Omirror-pov.exr +FE +W$w +H$h -A >"$tmp/pov.log" 2>&1) \
  || { sed 's/^/  | /' "$tmp/pov.log" | tail -20; fail "povray could not render the mirror"; }
mirror 1 0.005
mirror 0.5 0.02
"$limn" capture --scene cornell_mirror --script scripts/pp.lua --tech dl --set ambient=0 --size $size \
  --output "$tmp/mirror-off.exr" --quiet || fail "capture mirror without reflections"
"$limn" compare "$tmp/mirror-off.exr" "$tmp/mirror-pov.exr" --json >"$tmp/m.json" || fail "compare mirror off"
off=$(num mean_error)
echo "mirror without reflections: mean error $off"
awk -v m="$off" 'BEGIN { exit !(m > 0.04) }' || fail "the mirror matters too little ($off) for the bound to mean anything"

# The radiosity export parses and renders (small and coarse to stay fast),
# and its indirect light changes the image while the geometry stays put.
"$limn" export-pov --scene cornell_pov --size 32x24 --count 20 --output "$tmp/gi.pov" || fail "export-pov radiosity"
"$limn" export-pov --scene cornell_pov --size 32x24 --radiosity off --output "$tmp/nogi.pov" || fail "export-pov"
(cd "$tmp" && povray -D -V +Igi.pov +Ogi.exr +FE +W32 +H24 -A >"$tmp/gi.log" 2>&1 &&
  povray -D -V +Inogi.pov +Onogi.exr +FE +W32 +H24 -A >>"$tmp/gi.log" 2>&1) \
  || { sed 's/^/  | /' "$tmp/gi.log" | tail -20; fail "povray could not render the radiosity export"; }
grep -q "Radiosity Time" "$tmp/gi.log" || fail "no radiosity pass in POV-Ray's log"
"$limn" compare "$tmp/nogi.exr" "$tmp/gi.exr" --json >"$tmp/m.json" || fail "compare gi"
cat "$tmp/m.json"
mean=$(num mean_error) pearson=$(num pearson)
echo "POV-Ray with radiosity against without at 32x24: mean error $mean, Pearson $pearson"
awk -v m="$mean" 'BEGIN { exit !(m > 0.01) }' || fail "radiosity changes nothing (mean error $mean)"
awk -v p="$pearson" 'BEGIN { exit !(p > 0.9) }' || fail "radiosity image unlike the direct one (Pearson $pearson)"
echo "passed"
