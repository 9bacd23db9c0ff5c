#!/usr/bin/env bash
# BVMesh set-up for Debian 12 (as root, or with sudo available). Every step is idempotent and
# quick when nothing changed:
#   bash scripts/setup.sh example   install packages, build, register the workbench, run the main job
#   bash scripts/setup.sh test      install packages, build, register the workbench, run every test (ctest)
#   bash scripts/setup.sh build     install packages, build, register the workbench
#   bash scripts/setup.sh gui       the same, then start the FreeCAD GUI (the BVMesh workbench is in its list)
#   bash scripts/setup.sh cfd       the same as build, then the OpenFOAM euler run on the M6 grid (all cores,
#                                   at most BVMESH_CFD_SECONDS, default 3600) and its report in build/cfd/
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD_DIR=${BVMESH_BUILD_DIR:-$ROOT/build}
PACKAGES=(
  build-essential cmake ninja-build
  freecad libocct-modeling-algorithms-dev libocct-modeling-data-dev libocct-foundation-dev
  libocct-data-exchange-dev libeigen3-dev libosd-dev libtbb-dev libsuitesparse-dev pybind11-dev python3-dev
  libgtest-dev
  python3-numpy python3-scipy python3-matplotlib xvfb xauth imagemagick
  libcgns-dev libhdf5-dev cgns-convert openfoam python3-vtk9 python3-h5py
)

say() { printf '[bvmesh] %s\n' "$*"; }

install_packages() {
  local missing=()
  for package in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" || missing+=("$package")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    say "Debian packages: all present"
    return
  fi
  say "installing Debian packages: ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q "${missing[@]}"
}

build() {
  if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
    say "configuring $BUILD_DIR"
    cmake -S "$ROOT" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBVMESH_WERROR=ON \
      -DPython_EXECUTABLE=/usr/bin/python3
  fi
  say "building"
  cmake --build "$BUILD_DIR" -j "$(nproc)"
}

# FreeCAD 0.20 reads user workbenches from ~/.local/share/FreeCAD/Mod (not ~/.FreeCAD/Mod).
register_workbench() {
  local mod_dir="$HOME/.local/share/FreeCAD/Mod"
  mkdir -p "$mod_dir"
  ln -sfn "$ROOT" "$mod_dir/BVMesh"
  say "workbench registered: $mod_dir/BVMesh -> $ROOT"
}

run_python() {
  PYTHONPATH="$ROOT/Mod:/usr/lib/freecad-python3/lib${PYTHONPATH:+:$PYTHONPATH}" /usr/bin/python3 "$@"
}

command=${1:-}
case "$command" in
  build | example | test | gui | cfd) ;;
  *) sed -n '2,10p' "$0" >&2; exit 2 ;;
esac

install_packages
build
register_workbench
case "$command" in
  example) run_python -m bvmesh example --output "$ROOT/build/example" ;;
  test) ctest --test-dir "$BUILD_DIR" --output-on-failure --timeout 900 ;;
  gui) exec freecad ;;
  cfd) run_python -m bvmesh openfoam-case "$ROOT/build/cfd/m6_euler" --iterations 4000 --write-interval 100 \
         --run --cores "$(nproc)" --timeout "${BVMESH_CFD_SECONDS:-3600}" --report "$ROOT/build/cfd" ;;
esac
