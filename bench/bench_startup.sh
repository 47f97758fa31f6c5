#!/bin/sh
# Start-up time of the evlife tool (issue 12): median of 7 runs of
# `evlife --help` and of `evlife process` on a 3-event file, in ms; with perf,
# their page faults and CPU time.
#   bench/bench_startup.sh [build/engine/evlife]
. "$(dirname "$0")/usage.sh"
set -eu
cli=${1:-build/engine/evlife}
need_executable "$cli"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf '0.000001 1 1 1\n0.000002 2 2 0\n0.000003 3 3 1\n' > "$tmp/three.txt"
# A command that fails is timed as nothing: it ends the script, named.
median_ms() {
  : > "$tmp/times"
  for _ in 1 2 3 4 5 6 7; do
    t0=$(date +%s%N)
    if ! "$@" > /dev/null 2> "$tmp/stderr"; then
      echo "$(basename "$0"): '$*' failed: $(tail -c 300 "$tmp/stderr")" >&2
      exit 1
    fi
    t1=$(date +%s%N)
    echo $(( (t1 - t0) / 1000 )) >> "$tmp/times"
  done
  sort -n "$tmp/times" | sed -n 4p | awk '{ printf "%.1f", $1 / 1000 }'
}
help_ms=$(median_ms "$cli" --help)  # an assignment: a failure ends the script (set -e)
process_ms=$(median_ms "$cli" process "$tmp/three.txt" --sensor 8x8 -o "$tmp/three.bin" -q)
echo "evlife --help: $help_ms ms"
echo "evlife process (3 events): $process_ms ms"
# ldd's lines: the libraries ("=> /path") plus the loader and the vDSO.
echo "shared libraries loaded: $(ldd "$cli" | wc -l) ldd lines ($(ldd "$cli" | grep -c '=> /') libraries, the loader and the vDSO)"
# Page faults and CPU of each start (perf, from Debian's linux-perf, when the
# machine lets it count): where page faults are dear, they are the start-up.
if command -v perf > /dev/null 2>&1; then
  for args in "--help" "process $tmp/three.txt --sensor 8x8 -o $tmp/three.bin -q"; do
    # shellcheck disable=SC2086 # the arguments split on purpose
    perf stat -r 7 -x, -e page-faults,task-clock "$cli" $args 2>&1 > /dev/null |
      awk -F, -v a="${args%% *}" '$3 == "page-faults" { f = $1 } $3 == "task-clock" { c = $1 }
        END { if (f != "") printf "evlife %s: %d page faults, %.1f ms CPU (perf stat -r 7)\n", a, f, c }'
  done
fi
