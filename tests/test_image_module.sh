#!/usr/bin/env bash
# OpenImageIO stays out of a capture that reads PNG textures and
# writes a PNG (engine/image/image.c): the dynamic loader's log (LD_DEBUG)
# of such a capture names neither OpenImageIO nor its module, while that of
# a capture writing an EXR names the module, and the EXR is there.
set -euo pipefail
limn=$1 root=$2
# shellcheck source=tests/shell_test.sh
. "$root/tests/shell_test.sh"
scratch image-module

capture() { # output, then the loader's log in $tmp/log
  LD_DEBUG=files LD_DEBUG_OUTPUT="$tmp/log" "$limn" capture --scene "$root/data/scenes/primitives.glb" \
    --tech dl+esm --size 64x48 --frames 1 --quiet --output "$1"
  cat "$tmp"/log.* >"$tmp/log" && rm -f "$tmp"/log.*
}
loaded() { grep -q -e OpenImageIO -e limn_image_oiio "$tmp/log"; }
not() { ! "$@"; }

capture "$tmp/frame.png"
check "the PNG was written" test -s "$tmp/frame.png"
check "the loader opened files (its log is read)" grep -q "file=" "$tmp/log"
check "no OpenImageIO for textures and a PNG" not loaded
capture "$tmp/frame.exr"
check "the EXR was written" test -s "$tmp/frame.exr"
check "the module opened for an EXR" grep -q "limn_image_oiio.*dynamically loaded" "$tmp/log"
finish
