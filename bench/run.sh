#!/usr/bin/env bash
# Builds and runs every benchmark; results go to build/bench-results/<name>.txt. Each benchmark
# measures its own baselines in the same run and reports ratios against them.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=${BVMESH_BUILD_DIR:-$ROOT/build}
OUT=$BUILD/bench-results
mkdir -p "$OUT"
cmake --build "$BUILD" -j "$(nproc)"
export PYTHONPATH="$ROOT/Mod:/usr/lib/freecad-python3/lib"
for bench in "$BUILD"/bench/bench_*; do
  [ -x "$bench" ] || continue
  name=$(basename "$bench")
  echo "== $name"
  "$bench" | tee "$OUT/$name.txt"
done
for script in "$ROOT"/bench/bench_*.py; do
  name=$(basename "$script" .py)
  echo "== $name"
  /usr/bin/python3 "$script" | tee "$OUT/$name.txt"
done
