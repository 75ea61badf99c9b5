#!/usr/bin/env bash
# GPU figures of the moving-camera benchmark on a lent GPU machine (the
# `device` tool), never a test dependency. Two steps:
#   tools/device_bench.sh prepare [BASE_REV]
#       here: builds `limn` without OpenImageIO (LIMN_IMAGE_IO=OFF: PNG and JPEG only;
#       its libraries are too big to carry) from the working tree into
#       .devcheck/head, and from BASE_REV (if given) into .devcheck/base, and
#       copies the libraries they load into .devcheck/lib (libEGL and libGL
#       from glvnd, so that the machine's NVIDIA driver is the one loaded).
#   tools/device_bench.sh run [SIZE]
#       there (device run with carry .devcheck): NVIDIA's EGL device platform,
#       then `limn bench --motion --clock gpu` per scene at SIZE (default
#       1920x1080), base and head taking turns, each pass's GPU time moving.
#       TECHS (default isr+esm), SCENES and ROUNDS (default 2) choose the runs.
#   tools/device_bench.sh memory FILE...
#       there: peak resident memory, time to first frame and GPU memory of
#       `limn bench` (dl+esm and the default, 640x480) per scene file, base
#       (when prepared) and head taking turns.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=.devcheck

build_without_images() { # source folder, build folder
  cmake -S "$1" -B "$2" -DLIMN_IMAGE_IO=OFF -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$2" -j "$(nproc)" --target limn >/dev/null
}

prepare() {
  rm -rf "$dir" && mkdir -p "$dir/lib"
  build_without_images . build-device
  mkdir -p "$dir/head" && cp build-device/limn "$dir/head/"
  if [ -n "${1:-}" ]; then
    local wt=/tmp/limn-device-base
    git worktree remove --force "$wt" 2>/dev/null || true
    git worktree add -q --detach "$wt" "$1"
    # A revision older than LIMN_IMAGE_IO: swap its image bridge for the libpng stub that
    # LIMN_IMAGE_IO=OFF built until engine/image/image.c replaced it.
    if ! grep -q LIMN_IMAGE_IO "$wt/CMakeLists.txt"; then
      local gone
      gone=$(git log -1 --format=%H --diff-filter=D HEAD -- engine/image/image_png.c)
      git show "$gone^:engine/image/image_png.c" >"$wt/engine/image/image_png.c"
      sed -i -e 's|engine/image/image_oiio.cpp|engine/image/image_png.c|' -e 's|PkgConfig::OIIO|png16|' \
        -e '/pkg_check_modules(OIIO/d' -e '/add_subdirectory(tests)/d' "$wt/CMakeLists.txt"
    fi
    build_without_images "$wt" "$wt/build-device"
    mkdir -p "$dir/base/root" && cp "$wt/build-device/limn" "$dir/base/"
    # Its own scripts and shaders (LIMN_ROOT): the working tree's may not suit it.
    git archive "$1" scripts shaders | tar -x -C "$dir/base/root"
    git worktree remove --force "$wt"
  fi
  ldd "$dir"/*/limn | awk '/=> \// {print $3}' | sort -u | grep -v -e 'libc\.so' -e 'libm\.so' -e 'ld-linux' |
    xargs -r cp -L -t "$dir/lib"
  # libepoxy opens GL and EGL at run time (not in ldd): glvnd's, which load the machine's driver.
  local gl
  for gl in libEGL.so.1 libGL.so.1 libGLX.so.0 libGLdispatch.so.0 libOpenGL.so.0; do
    cp -L "/usr/lib/$(gcc -print-multiarch)/$gl" "$dir/lib/"
  done
  # Embree alone is 43 MB: packed, the folder fits the device tool's 64 MiB carry.
  tar -C "$dir" -cf - lib | xz -T0 -6 >"$dir/lib.tar.xz" && rm -rf "$dir/lib"
  du -sh "$dir"
  echo "device: run with carry [\"$dir\"]: tools/device_bench.sh run"
}

use_nvidia() { # glvnd's libraries from .devcheck, the machine's NVIDIA EGL vendor
  [ -d "$dir/lib" ] || tar -C "$dir" -xJf "$dir/lib.tar.xz"
  export LIMN_ROOT=$PWD LD_LIBRARY_PATH=$PWD/$dir/lib
  local f
  for f in /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json /usr/share/glvnd/egl_vendor.d/10_nvidia.json; do
    [ -f "$f" ] && export __EGL_VENDOR_LIBRARY_FILENAMES=$f && break
  done
  nvidia-smi -L || true
}

memory() {
  use_nvidia
  local revs=(head)
  [ -x "$dir/base/limn" ] && revs=(base head)
  local file tech rev
  for file in "$@"; do
    for tech in dl+esm default; do
      local args=(--scene "$file" --sizes 640x480 --frames 4 --warmup 1)
      [ "$tech" = default ] || args+=(--tech "$tech")
      for rev in "${revs[@]}"; do
        echo "== $rev: $file $tech"
        local root=$PWD
        [ -d "$dir/$rev/root" ] && root=$PWD/$dir/$rev/root
        LIMN_ROOT=$root timeout 150 "$dir/$rev/limn" bench "${args[@]}" 2>&1 |
          grep -i -e 'peak' -e 'first frame' -e 'gpu memory' || echo "  failed"
      done
    done
  done
}

run() {
  local size=${1:-1920x1080} out=${OUT:-/tmp}/device_bench
  mkdir -p "$out"
  use_nvidia
  local revs=(head)
  [ -x "$dir/base/limn" ] && revs=(base head)
  local scene tech round
  for scene in ${SCENES:-cornell data/scenes/office.glb data/scenes/garage.glb data/scenes/outdoor.glb}; do
   for tech in ${TECHS:-isr+esm}; do
    for round in $(seq "${ROUNDS:-2}"); do
      for rev in "${revs[@]}"; do
        echo "== $rev round $round: $scene $tech $size moving"
        # Whole tables to $OUT (the device tool brings them back); here the moving column.
        local log="$out/$(basename "$scene" .glb)-$tech-$rev-$round.txt"
        local root=$PWD
        [ -d "$dir/$rev/root" ] && root=$PWD/$dir/$rev/root
        LIMN_ROOT=$root timeout 150 "$dir/$rev/limn" bench --motion --clock gpu --scene "$scene" --tech "$tech" --sizes "$size" \
          --frames 24 --warmup 4 >"$log" 2>&1 || echo "  failed: $(tail -1 "$log")"
        awk '/^motion at/ {on=1} on && /pass \(ms\)/ {t=1; next} /shadow tiles drawn/ {t=0}
             t { name=$1; for (i=2; i<=NF-5; i++) name=name " " $i; printf "  %-24s %s\n", name, $(NF-3) }' "$log"
      done
    done
   done
  done
}

case "${1:-}" in
  prepare) shift; prepare "$@" ;;
  run) shift; run "$@" ;;
  memory) shift; memory "$@" ;;
  *) sed -n '2,16p' "$0" >&2; exit 2 ;;
esac
