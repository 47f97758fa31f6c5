#!/bin/sh
# Engine scaling as a whole process (issue 12): `evlife run --workers 1` vs
# `--workers 2` on a 240x180 synthetic scene of 1.27 M events (`evlife synth
# --scene large`, 0.6 s), output to .bin; runs alternate, median of N each.
# Prints wall and CPU (user + sys) seconds, the wall ratio, the CPU seconds of
# each engine thread (the summary's `cpu` line, medians), the workers' CPU ns
# per event in the estimator (last run) and checks that both outputs are
# identical byte for byte to each other and to `evlife process`.
#
# Input format (3rd argument): `dat` (default) replays the scene as a
# Prophesee DAT file (8-byte records, what a camera's recording costs to
# decode; written from `evlife synth`'s text output by Debian's numpy, as evlife
# writes no DAT); `h5` replays synth's HDF5 file, whose zlib inflate costs the
# source thread ~0.04 s more CPU, taken from the two cores the workers use.
# The previous output file is removed before each run, outside the timing.
# Wall times need an otherwise idle machine; the CPU figures hold under load.
#   bench/bench_workers.sh [build/engine/evlife] [runs] [dat|h5]
. "$(dirname "$0")/usage.sh"
set -eu
cli=${1:-build/engine/evlife}
runs=${2:-5}
format=${3:-dat}
need_executable "$cli"
need_count runs "$runs"
need_time
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
synth="--scene large --sensor 240x180 --duration 0.6 --quiet"
case "$format" in
  h5) "$cli" synth -o "$tmp/scene.h5" $synth; scene="$tmp/scene.h5" ;;
  dat)
    "$cli" synth -o "$tmp/scene.txt" $synth
    /usr/bin/python3 - "$tmp/scene.txt" "$tmp/scene.dat" <<'EOF'
import sys
import numpy as np
v = np.array(open(sys.argv[1], 'rb').read().split(), dtype=np.float64).reshape(-1, 4)  # t x y p
t = np.rint(v[:, 0] * 1e6).astype('<u4')  # 6 decimals of a second: exact us
word = v[:, 1].astype('<u4') | (v[:, 2].astype('<u4') << 14) | (v[:, 3].astype('<u4') << 28)
records = np.empty(2 * len(t), dtype='<u4')
records[0::2], records[1::2] = t, word
with open(sys.argv[2], 'wb') as f:
    f.write(b'% Data file containing CD events.\n% Version 2\n% Width 240\n% Height 180\n')
    f.write(bytes([0x0C, 8]))  # CD events, 8-byte records
    f.write(records.tobytes())
EOF
    scene="$tmp/scene.dat" ;;
  *) echo "format: dat or h5" >&2; exit 2 ;;
esac
one_run() {  # workers -> "wall cpu source w0 [w1] merger other" seconds; engine log in $tmp/log.W
  rm -f "$tmp/out$1.bin"
  /usr/bin/time -f '%e %U %S' -o "$tmp/time" "$cli" run --source "file:$scene" --workers "$1" --sensor 240x180 \
    -o "$tmp/out$1.bin" > "$tmp/log$1" 2>&1
  threads=$(grep '^cpu' "$tmp/log$1" | sed 's/; other (start-up, main)/, other/; s/;.*//; s/^cpu *: //' |
    tr ',' '\n' | awk '{ printf " %s", $2 }')
  awk -v t="$threads" '{ printf "%s %.2f%s\n", $1, $2 + $3, t }' "$tmp/time"
}
: > "$tmp/w1"; : > "$tmp/w2"
i=0
while [ "$i" -lt "$runs" ]; do
  one_run 1 >> "$tmp/w1"
  one_run 2 >> "$tmp/w2"
  i=$((i + 1))
done
med() { sort -n -k"$2" "$1" | sed -n "$(( (runs + 1) / 2 ))p" | cut -d' ' -f"$2"; }
w1=$(med "$tmp/w1" 1); w2=$(med "$tmp/w2" 1)
echo "input: $format; $(grep '^source' "$tmp/log1" | cut -d, -f1)"
echo "workers 1: wall $w1 s, cpu $(med "$tmp/w1" 2) s (median of $runs)"
echo "workers 2: wall $w2 s, cpu $(med "$tmp/w2" 2) s (median of $runs)"
echo "speed-up (wall 1 / wall 2): $(echo "$w1 $w2" | awk '{ printf "%.2f", $1 / $2 }')x"
echo "CPU s per thread, medians: workers 1: source $(med "$tmp/w1" 3), worker0 $(med "$tmp/w1" 4)," \
  "merger $(med "$tmp/w1" 5), start-up+main $(med "$tmp/w1" 6)"
echo "                           workers 2: source $(med "$tmp/w2" 3), worker0 $(med "$tmp/w2" 4)," \
  "worker1 $(med "$tmp/w2" 5), merger $(med "$tmp/w2" 6), start-up+main $(med "$tmp/w2" 7)"
for w in 1 2; do echo "workers $w, last run:"; grep '^worker' "$tmp/log$w" | sed 's/, dropped.*//'; done
"$cli" process "$scene" -o "$tmp/process.bin" --quiet
cmp "$tmp/out1.bin" "$tmp/out2.bin" && cmp "$tmp/out1.bin" "$tmp/process.bin" &&
  echo "outputs identical (workers 1, workers 2, evlife process)"
