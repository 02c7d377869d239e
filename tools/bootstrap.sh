#!/usr/bin/env bash
# Sets up a Debian 12 machine for meshstream and builds it, then runs one job:
#   tools/bootstrap.sh demo   install what is missing, build the command, decimate the bunny fixture to 10 % as .glb
#   tools/bootstrap.sh test   install what is missing, build, run the whole test suite (ctest)
#   tools/bootstrap.sh build  install what is missing and build only
# Idempotent: packages already installed and an up-to-date build are not redone.
# MESHSTREAM_CMAKE_ARGS adds configure options to a new build (CI: -DMESHSTREAM_WERROR=ON).
set -euo pipefail
cd "$(dirname "$0")/.."

mode=${1:-build}
case "$mode" in
  demo | test | build) ;;
  *) echo "usage: $0 demo|test|build" >&2; exit 2 ;;
esac
build_dir=${MESHSTREAM_BUILD_DIR:-build}
tools_dir=${MESHSTREAM_TOOLS_DIR:-/opt/meshstream-tools}   # npm tools used by the tests
jobs=$(nproc 2>/dev/null || echo 2)

as_root() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

# Debian packages: build tools, libraries, and the real clients the tests check output with
# (draco_decoder; Chromium renders the GLBs the tests write with three.js); OpenMPI for
# meshstream-mpi and its tests (mpirun); pybind11, numpy and pytest for the Python package
# (python/), Open3D and meshio for its interop tests.
packages="cmake g++ make pkg-config libgtest-dev zlib1g-dev libdraco-dev draco libtinygltf-dev \
nlohmann-json3-dev libcli11-dev libmeshoptimizer-dev chromium libopenmpi-dev openmpi-bin \
pybind11-dev python3-dev python3-numpy python3-pytest python3-open3d python3-meshio"
command -v node >/dev/null 2>&1 || packages="$packages nodejs"
command -v npm >/dev/null 2>&1 || packages="$packages npm"
missing=""
for p in $packages; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "meshstream setup: installing$missing" >&2
  as_root apt-get update -qq
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $missing >/dev/null
fi

# npm tools: the Khronos glTF validator, which the tests run on every glTF they write; three.js,
# whose GLTFLoader (with MeshoptDecoder and DRACOLoader) renders them in Chromium, and
# 3d-tiles-renderer, which loads the tilesets of `meshstream tiles` there as viewers do; gltfpack,
# the size reference of bench/web.sh.
for pkg in gltf-validator@2.0.0-dev.3.10 three@0.170.0 3d-tiles-renderer@0.5.3 gltfpack@0.18.0; do
  name=${pkg%@*}
  if [ "$(node -p "try { require('$tools_dir/node_modules/$name/package.json').version } catch (e) { '' }" 2>/dev/null)" != "${pkg##*@}" ]; then
    echo "meshstream setup: installing $pkg into $tools_dir" >&2
    as_root mkdir -p "$tools_dir"
    as_root npm install --silent --no-audit --no-fund --prefix "$tools_dir" "$pkg" >/dev/null
  fi
done

# The official 3D Tiles validator, which the tests run on the tilesets `meshstream tiles` writes:
# from its source beside the checkout (../shared/peers, on development and CI machines), built
# from npm packages alone; its setup does nothing when it is already there.
validator_source=../shared/peers/3d-tiles-validator
if [ "$mode" = test ] && [ -x "$validator_source/setup.sh" ]; then
  as_root bash "$validator_source/setup.sh" "$tools_dir/3d-tiles-validator" >/dev/null
fi

if [ ! -f "$build_dir/CMakeCache.txt" ]; then
  # shellcheck disable=SC2086  # MESHSTREAM_CMAKE_ARGS is a list of options
  cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DMESHSTREAM_TOOLS_DIR="$tools_dir" \
    ${MESHSTREAM_CMAKE_ARGS:-} >/dev/null
fi
# The demo builds the one program it runs; the test suite and `build` build everything.
case "$mode" in
  demo) cmake --build "$build_dir" -j"$jobs" --target meshstream ;;
  build | test) cmake --build "$build_dir" -j"$jobs" ;;
esac

case "$mode" in
  build) ;;
  demo)
    "$build_dir/tools/meshstream" decimate fixtures/bunny_from_draco.bin.stl bunny_10.glb --ratio 0.1
    "$build_dir/tools/meshstream" info bunny_10.glb
    ;;
  test)
    ctest --test-dir "$build_dir" --output-on-failure -j"$jobs"
    ;;
esac
