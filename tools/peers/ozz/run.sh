#!/usr/bin/env bash
# ozz-animation (guillaumeblanc/ozz-animation) on the CMU 01_01 BVH clip:
# runtime bytes, error, and the time to sample a pose forward at 60 fps.
# Rebuilds ozz from a git directory of its sources with g++ (no cmake) and
# reruns everything. Modelled on ../shared/peers/acl/run.sh.
#
#   OZZ_GIT=<git dir of guillaumeblanc/ozz-animation> bash tools/peers/ozz/run.sh
#
# Environment (all optional but OZZ_GIT):
#   OZZ_GIT  git dir (bare or not) of guillaumeblanc/ozz-animation
#   OZZ_REF  ozz commit-ish to use         (default HEAD of the mirror)
#   BVH      the clip                      (default data/cmu-01_01.bvh, run from the project root)
#   WORK     sources, builds and results   (default ${TMPDIR:-/tmp}/peer-ozz)
#   RUNS     interleaved repeats per row   (default 3; timings: median over runs)
#   ROUNDS   timing rounds per run         (default 51)
#   SLICE_MS ms per round and subject      (default 20)
#   CXXFLAGS extra g++ flags, e.g. "-march=x86-64-v3" (default none: x86-64,
#            SSE2, as tcb's default build; ozz picks its SIMD path from them)
#   JOBS     parallel g++ processes        (default nproc)
#   PIN      command prefix, e.g. "taskset -c 1" (default none)
#
# What is built: every .cc of ozz's src/base, src/animation/runtime and
# src/animation/offline (not its fbx/, gltf/ or tools/ folders), -std=c++17
# -O3 -DNDEBUG as ozz's CMake release build, linked with ozz_bench.cc.
set -euo pipefail

HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
BVH=$(readlink -f "${BVH:-data/cmu-01_01.bvh}")
WORK=${WORK:-${TMPDIR:-/tmp}/peer-ozz}
RUNS=${RUNS:-3}
ROUNDS=${ROUNDS:-51}
SLICE_MS=${SLICE_MS:-20}
OZZ_REF=${OZZ_REF:-HEAD}
CXXFLAGS=${CXXFLAGS:-}
JOBS=${JOBS:-$(nproc)}
PIN=${PIN:-}
: "${OZZ_GIT:?set OZZ_GIT to the git dir of guillaumeblanc/ozz-animation}"

log() { printf '== %s\n' "$*" >&2; }

for t in g++ git python3; do
  command -v "$t" >/dev/null 2>&1 || { echo "run.sh: needs $t" >&2; exit 1; }
done
[ -f "$BVH" ] || { echo "run.sh: missing $BVH" >&2; exit 1; }

# --- sources ---------------------------------------------------------------
[ -d "$OZZ_GIT" ] || { echo "run.sh: missing git dir $OZZ_GIT" >&2; exit 1; }
OZZ_COMMIT=$(git --git-dir="$OZZ_GIT" rev-parse "$OZZ_REF^{commit}")
OZZ_DESCRIBE=$(git --git-dir="$OZZ_GIT" describe --tags "$OZZ_COMMIT" 2>/dev/null || echo '?')
SRC=$WORK/src
rm -rf "$SRC"
mkdir -p "$SRC"
# Only the folders built: a mirror may lack the large media files.
git --git-dir="$OZZ_GIT" archive "$OZZ_COMMIT" include src/base src/animation/runtime src/animation/offline 2>/dev/null |
  tar -x -C "$SRC"
log "ozz $OZZ_COMMIT ($OZZ_DESCRIBE)"

# --- build -------------------------------------------------------------------
BUILD=$WORK/build
rm -rf "$BUILD"
mkdir -p "$BUILD/obj"
# shellcheck disable=SC2206
FLAGS=(-std=c++17 -O3 -DNDEBUG -Wall -Wno-ignored-attributes $CXXFLAGS -I"$SRC/include" -I"$SRC/src")
log "g++ ${FLAGS[*]} ($JOBS at a time)"
# One g++ per file, JOBS at a time; a file's messages go to its .log (ozz's
# simd_math.cc always prints which SIMD path it was built with), shown if it fails.
(cd "$SRC/src" && ls base/*.cc base/*/*.cc animation/runtime/*.cc animation/offline/*.cc) |
  xargs -P "$JOBS" -I{} sh -c 'f=$1 s=$2 d=$3; shift 3; o=$d/$(echo "${f%.cc}" | tr / _)
    g++ "$@" -c "$s/$f" -o "$o.o" 2>"$o.log" || { cat "$o.log" >&2; exit 1; }' \
    sh {} "$SRC/src" "$BUILD/obj" "${FLAGS[@]}"
grep -ho 'Ozz libraries were built with [A-Za-z0-9_. ]*' "$BUILD/obj/base_maths_simd_math.log" | head -1 >&2 || true
g++ "${FLAGS[@]}" "$HERE/ozz_bench.cc" "$BUILD"/obj/*.o -o "$BUILD/ozz_bench"
log "built $(ls "$BUILD"/obj/*.o | wc -l) ozz objects and $BUILD/ozz_bench"

# --- machine info ----------------------------------------------------------------
RES=$WORK/results-$(date +%Y%m%d-%H%M%S)
mkdir -p "$RES"
{
  echo "ozz_commit $OZZ_COMMIT"
  echo "ozz_describe $OZZ_DESCRIBE"
  echo "cpu $(sed -n 's/^model name\s*: //p' /proc/cpuinfo | head -1)"
  echo "cxx $(g++ --version | head -1)"
  echo "flags ${FLAGS[*]:0:3} $CXXFLAGS"
  echo "date $(date -u +%FT%TZ)"
  echo "loadavg $(cut -d' ' -f1-3 /proc/loadavg)"
  echo "bvh $BVH $(sha1sum "$BVH" | cut -c1-12)"
} | tee "$RES/info.txt" >&2

# --- the rows ------------------------------------------------------------------
# 31j: the 31 joints tcb animates; 38j: and the 7 End Sites, as ACL's rows;
# 31j_acl: the optimizer at ACL's default error (0.01 cm at a 3 cm shell), the
# target of tcb's character-compressed-acl. Each also times the AnimationBuilder
# output of every key. Units: BVH units, 1 unit = 6.627 cm.
# name | args
ROWS=(
  "31j|"
  "38j|--end-sites"
  "31j_acl|--tolerance-cm 0.01 --distance-cm 3"
)
for ((r = 1; r <= RUNS; ++r)); do
  for row in "${ROWS[@]}"; do
    name=${row%%|*} args=${row#*|}
    log "run $r/$RUNS $name"
    # shellcheck disable=SC2086
    $PIN "$BUILD/ozz_bench" $args --rounds "$ROUNDS" --slice-ms "$SLICE_MS" \
      --json "$RES/$name.run$r.json" "$BVH" >"$RES/$name.run$r.txt"
  done
done
echo "loadavg_end $(cut -d' ' -f1-3 /proc/loadavg)" >>"$RES/info.txt"
cat "$RES/31j.run1.txt" >&2

python3 "$HERE/table.py" "$RES" | tee "$RES/table.md"
log "results in $RES"
