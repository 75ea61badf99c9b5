#!/usr/bin/env bash
# Rewrites the golden images that tests/test_render.c compares against.
# Run after a deliberate change to the default pipeline's look; review the
# new images before committing them.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$here/build}
"$build/limn" capture --scene cornell --script "$here/scripts/pp.lua" --tech dl --size 256x192 \
  --quiet --output "$here/data/golden/cornell_dl.png"
echo "wrote data/golden/cornell_dl.png"
