#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, -DBVMESH_FUZZ=ON with clang-14, in build-fuzz/) and runs one:
#   bash scripts/fuzz.sh TARGET SECONDS [extra libFuzzer options]
# TARGET: step, iges, brep, cmesh, obj or control_mesh. The run is niced, single-job (-fork=1: one
# child at a time that libFuzzer restarts after a crash, a timeout or running out of memory, so a
# run lasts SECONDS and collects every finding), with a memory limit and a per-input timeout.
# Kept in build-fuzz/: corpus/TARGET (grows), seeds/TARGET (made from tests/data and the core's
# writers), artifacts/TARGET (crash-*, timeout-*, oom-* inputs), logs/TARGET-*.log.
# Reproduce one finding: build-fuzz/fuzz/fuzz_TARGET build-fuzz/artifacts/TARGET/crash-...
# OCCT prints to stdout: the target's stdout is closed (-close_fd_mask=1), libFuzzer reports on stderr.
# Not part of the build or of ctest. Environment: FUZZ_RSS_MB (2048), FUZZ_TIMEOUT (20 s per input).
set -euo pipefail

targets="step iges brep cmesh obj control_mesh"
if [ $# -lt 2 ] || [[ " $targets " != *" $1 "* ]] || ! [[ $2 =~ ^[0-9]+$ ]]; then
  echo "usage: bash scripts/fuzz.sh TARGET SECONDS [libFuzzer options]; TARGET one of: $targets" >&2
  exit 2
fi
target=$1 seconds=$2
shift 2

root=$(cd "$(dirname "$0")/.." && pwd)
build=$root/build-fuzz
sudo=""
[ "$(id -u)" -eq 0 ] || sudo=sudo

# clang-14 and its libFuzzer runtime (Debian 12 packages), installed when missing.
missing=()
command -v clang++-14 >/dev/null || missing+=(clang-14)
dpkg -s libclang-rt-14-dev >/dev/null 2>&1 || missing+=(libclang-rt-14-dev)
if [ ${#missing[@]} -gt 0 ]; then
  $sudo apt-get update
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y "${missing[@]}"
fi

# One build at a time on this machine (the lock every build takes).
lock=(flock /tmp/bvmesh-build.lock)
command -v flock >/dev/null || lock=()
if [ ! -f "$build/build.ninja" ]; then
  "${lock[@]}" cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBVMESH_FUZZ=ON \
    -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_C_COMPILER=clang-14 -DBVMESH_WERROR=ON \
    -DBVMESH_BUILD_PYTHON=OFF -DBVMESH_BUILD_TESTS=OFF -DBVMESH_BUILD_BENCH=OFF \
    $(command -v ccache >/dev/null && echo -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
"${lock[@]}" cmake --build "$build" --target bvmesh_fuzz -j2

export ASAN_OPTIONS=detect_leaks=0:allocator_may_return_null=1  # OCCT keeps global caches
[ -d "$build/seeds/$target" ] || "$build/fuzz/bvmesh_fuzz_seeds" "$build/seeds"
mkdir -p "$build/corpus/$target" "$build/artifacts/$target" "$build/logs"
[ -d /dev/shm ] && export TMPDIR=/dev/shm  # the CAD targets write each input to a file there
log=$build/logs/$target-$(date +%Y%m%d-%H%M%S).log
echo "fuzz_$target for $seconds s, log $log"
nice -n 19 "$build/fuzz/fuzz_$target" -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
  -rss_limit_mb="${FUZZ_RSS_MB:-2048}" -timeout="${FUZZ_TIMEOUT:-20}" -max_total_time="$seconds" \
  -max_len=65536 -close_fd_mask=1 -print_final_stats=1 -artifact_prefix="$build/artifacts/$target/" "$@" \
  "$build/corpus/$target" "$build/seeds/$target" 2>&1 | tee "$log" | grep --line-buffered -E "^#|crash|CRASH|ERROR|Done" || true
echo "findings in $build/artifacts/$target:"
ls "$build/artifacts/$target"
