#!/bin/sh
# CPU time of a build, by top-level directory: configures a fresh Ninja build
# dir with the given CMake arguments, builds it (-j2, as CI), and sums the
# per-step times of its .ninja_log (a step's wall time, one core each).
# Compare two settings in one session, e.g. the test bodies' optimization:
#   bench/build_cost.sh /tmp/cost-og
#   bench/build_cost.sh /tmp/cost-o3 -DEVLIFE_TEST_BODY_OPTIMIZATION=
. "$(dirname "$0")/usage.sh"
set -eu
[ $# -ge 1 ] || { echo "usage: bench/build_cost.sh BUILD_DIR [CMAKE_ARGS...]" >&2; exit 2; }
root=$(cd "$(dirname "$0")/.." && pwd)
dir=$1
shift
rm -rf "$dir"
cmake -S "$root" -B "$dir" -G Ninja -DEVLIFE_WERROR=ON "$@" > "$dir.configure.log"
start=$(date +%s)
cmake --build "$dir" -j2 > "$dir.build.log"
echo "built in $(( $(date +%s) - start )) s (wall); CPU-s by directory (.ninja_log): every step, compiling (.o)"
# (A step with several outputs has a line per output, the same start, end and
# command hash: counted once.)
awk 'NR > 1 && !seen[$1 " " $2 " " $3]++ {
       s = ($2 - $1) / 1000; split($4, part, "/"); d = part[1] == "" ? "(top)" : part[1]
       cpu[d] += s; all += s
       if ($4 ~ /\.o$/) { objects[d] += s; all_objects += s } }
     END { for (d in cpu) printf "  %-10s %7.1f %7.1f\n", d, cpu[d], objects[d]
           printf "  %-10s %7.1f %7.1f\n", "total", all, all_objects }' "$dir/.ninja_log" | sort -k2 -rn
