#!/usr/bin/env bash
# One entry point for a fresh Debian 12 checkout:
#   tools/dev.sh run    install what is missing, build, render the Cornell box with the default
#                       technique, then error against time for dl+esm, the seed's ISR and the
#                       default against POV-Ray references (data/jobs/quick.lua, cached)
#   tools/dev.sh test   install what is missing, build, run the whole test suite
#   tools/dev.sh build  install what is missing and build
# BUILD_DIR (default build) and CMAKE_ARGS pass through to CMake, CTEST_ARGS to ctest;
# CTEST_JOBS is how many tests run at once (default: one a core).
set -euo pipefail
cd "$(dirname "$0")/.."

# Debian packages the build, the tests and the main job need.
packages=(
  build-essential cmake pkg-config git
  liblua5.4-dev libcglm-dev libopenimageio-dev libepoxy-dev
  libegl-dev libegl-mesa0 libgl1-mesa-dri libcmocka-dev libtinygltf-dev nlohmann-json3-dev
  libglfw3-dev libfreetype-dev fonts-dejavu-core xvfb xauth
  libimgui-dev                           # the viewer's panel (cli/view_panel.cpp, Dear ImGui)
  clang libclang-rt-14-dev povray valgrind libxml2-utils
  slurmctld slurmd slurm-client munge    # tests/test_slurm.sh starts a one-node cluster
  python3                                # tests read JSON and GLB with it (test_scenes_gen, test_tools_cli)
  libmeshoptimizer-dev                   # simplified shadow casters (engine/scene/scene.c)
  libdraco-dev                           # Draco-compressed glTF meshes (engine/scene/gltf_decode.cpp)
  libembree-dev                          # the ray tracer's acceleration structure (engine/trace, Embree 3)
  libpng-dev libjpeg-dev                 # PNG and JPEG without OpenImageIO (engine/image/image.c)
  blender                                # Cycles references (limn reference --renderer cycles, cli/cycles_render.py)
  python3-numpy                          # Blender's glTF importer and exporter (blender does not depend on it)
)

deps() {
  local missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  local cmd="apt-get update && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends ${missing[*]}"
  if [ "$(id -u)" -ne 0 ]; then
    echo "limn: missing Debian packages: ${missing[*]}" >&2
    echo "limn: install them as root, then run this again:" >&2
    echo "  sudo sh -c '$cmd'" >&2
    exit 1
  fi
  echo "limn: installing ${missing[*]}" >&2
  sh -c "$cmd" >&2
}

build() {
  local dir=${BUILD_DIR:-build}
  # shellcheck disable=SC2086
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo ${CMAKE_ARGS:-} >/dev/null
  cmake --build "$dir" -j "$(nproc)"
}

case "${1:-run}" in
  deps) deps ;;
  build) deps; build ;;
  run)
    deps; build
    mkdir -p out
    LIMN=${BUILD_DIR:-build}/limn
    # shellcheck source=tools/techniques.sh
    . tools/techniques.sh
    "$LIMN" capture --scene cornell --script scripts/pp.lua --tech "$(limn_default_technique)" --size 256x192 \
      --frames 5 --output out/cornell.png --output out/cornell.exr
    echo
    echo "Error against time on the reference set at 80x60, POV-Ray references (rendered once, cached in out/reference):"
    limn_gi_report out/quick data/jobs/quick.lua 3 "$LIMN_BASELINE=$LIMN_BASELINE" \
      "seed ISR=$(limn_seed_isr_spec)" "default=$(limn_default_spec)"
    ;;
  test)
    deps; build
    # Tests in parallel, one a core by default (CTEST_JOBS).
    # shellcheck disable=SC2086
    ctest --test-dir "${BUILD_DIR:-build}" --output-on-failure -j "${CTEST_JOBS:-$(nproc)}" ${CTEST_ARGS:-}
    ;;
  *) echo "usage: tools/dev.sh run|test|build|deps" >&2; exit 2 ;;
esac
