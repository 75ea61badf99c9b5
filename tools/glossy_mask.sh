#!/usr/bin/env bash
# tools/glossy_mask.sh: glossy indirect light on metals against Cycles (issue
# 32's target: glossy removes at least half of the error that direct light
# alone leaves on the metallic surfaces). For every view of SCENE, at SIZE,
# with materials = pbr and sky.lua's default sky: Cycles' reference (cached
# under REFS, rendered with the same sky and --materials pbr), a mask of the
# metallic surfaces (scripts/examples/mask.lua) and each setting below; then
# `limn compare --mask`'s mean error over the mask. Prints a row a view and
# the mean over the views, with the share of dl+esm's masked error each
# setting removes. A benchmark, not a test: it exits 0 when the run completes.
#   BUILD_DIR  the build (default build)     SCENE (default data/scenes/holdout/yard.glb)
#   SIZE       (default 96x72)               SAMPLES Cycles' samples a pixel (default 512)
#   REFS       the references (default out/glossy-refs: Cycles' pbr ones only, one a view)
#   OUT        the images (default out/glossy-mask)
set -euo pipefail
cd "$(dirname "$0")/.."
LIMN=${BUILD_DIR:-build}/limn
[ -x "$LIMN" ] || { echo "glossy_mask: no $LIMN (build first: tools/dev.sh build)" >&2; exit 2; }
SCENE=${SCENE:-data/scenes/holdout/yard.glb} SIZE=${SIZE:-96x72} SAMPLES=${SAMPLES:-512}
REFS=${REFS:-out/glossy-refs} OUT=${OUT:-out/glossy-mask}
SKY=0.1,0.15,0.3:0.3,0.32,0.35:1 # sky.lua's defaults, as the captures' sky.enabled=true
name=$(basename "$SCENE" .glb)
cams=${SCENE%.glb}.cams
[ -f "$cams" ] || { echo "glossy_mask: no $cams (the views)" >&2; exit 2; }
mkdir -p "$OUT"
cat > "$OUT/job.lua" <<LUA
return { scenes = { "$PWD/$SCENE" }, techniques = { "dl+esm" }, sizes = { "$SIZE" },
         set = { ambient = 0, materials = "pbr", ["sky.enabled"] = true }, output = "$PWD/$OUT/job/{camera}.png",
         references = { sky = "$SKY", materials = "pbr" } }
LUA
"$LIMN" reference --job "$OUT/job.lua" --refs "$REFS" --renderer cycles --samples "$SAMPLES" --quiet
settings=("dl+esm" "dl+esm:glossy.enabled=true" "lpv+esm" "lpv+esm:glossy.enabled=true"
          "lpv+esm:glossy.enabled=true,glossy.fallback=sky" "isr+lpv+esm:glossy.enabled=true")
printf "%-10s" view; for s in "${settings[@]}"; do printf " | %s" "$s"; done; echo
declare -A sum=()
views=0 index=0 # index: the camera's place in the file, as the glTF's cameras
while read -r cam _; do
  case "$cam" in ''|'#'*) continue ;; esac
  ref=$(ls -t "$REFS/$name/${cam}_${SIZE}-cycles-"*.exr | head -1)
  "$LIMN" capture --script scripts/examples/mask.lua --scene "$SCENE" --camera "$index" --size "$SIZE" \
    --output "$OUT/${cam}_mask.png" --quiet
  index=$((index + 1))
  if ! "$LIMN" compare "$OUT/${cam}_mask.png" "$OUT/${cam}_mask.png" --mask "$OUT/${cam}_mask.png" >/dev/null 2>&1; then
    echo "$cam: no metal in view, left out"
    continue
  fi
  row=$(printf "%-10s" "$cam")
  for spec in "${settings[@]}"; do
    args=(--tech "${spec%%:*}")
    if [ "$spec" != "${spec%%:*}" ]; then
      IFS=, read -r -a sets <<< "${spec#*:}"
      for s in "${sets[@]}"; do args+=(--set "$s"); done
    fi
    img="$OUT/${cam}_$(echo "$spec" | tr ':,=' '___').exr"
    "$LIMN" capture --scene "$SCENE" --camera "$((index - 1))" --size "$SIZE" "${args[@]}" --set ambient=0 \
      --set materials=pbr --set sky.enabled=true --output "$img" --quiet
    e=$("$LIMN" compare "$img" "$ref" --mask "$OUT/${cam}_mask.png" --json |
        sed -n 's/.*"masked_error": \([^,]*\),.*/\1/p')
    sum[$spec]=$(awk -v a="${sum[$spec]:-0}" -v b="$e" 'BEGIN { print a + b }')
    row+=$(printf " | %.5f" "$e")
  done
  echo "$row"
  views=$((views + 1))
done < "$cams"
base=$(awk -v s="${sum[dl+esm]}" -v n="$views" 'BEGIN { print s / n }')
printf "%-10s" mean
for s in "${settings[@]}"; do
  awk -v s="${sum[$s]}" -v n="$views" -v b="$base" 'BEGIN { m = s / n; printf " | %.5f (%.1f%% removed)", m, (b > 0 ? 100 * (b - m) / b : 0) }'
done
echo
echo "(masked mean error against Cycles' $SAMPLES-sample pbr references, $SIZE; removed: the share of dl+esm's)"
