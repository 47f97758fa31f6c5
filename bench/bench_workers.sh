#!/bin/sh
# Engine scaling as a whole process (issue 12): `evlife run --workers 1` vs
# `--workers 2` on a 240x180 synthetic scene of 1.27 M events (`evlife synth
# --scene large`, 0.6 s), output to .bin, --sensor given (else the sensor is
# scanned in a pass over the file before the engine starts); runs alternate,
# median of 5 each. Prints wall and CPU (user + sys) seconds, the wall ratio,
# the workers' CPU ns per event in the estimator (engine stats, last run) and
# checks that both outputs are identical byte for byte. Wall times need an
# otherwise idle machine; the CPU figures hold under load.
#   bench/bench_workers.sh [build/engine/evlife] [runs]
set -eu
cli=${1:-build/engine/evlife}
runs=${2:-5}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$cli" synth -o "$tmp/scene.h5" --scene large --sensor 240x180 --duration 0.6 --quiet
one_run() {  # workers -> "wall cpu" seconds; engine log in $tmp/log.W
  /usr/bin/time -f '%e %U %S' -o "$tmp/time" "$cli" run --source "file:$tmp/scene.h5" --workers "$1" --sensor 240x180 \
    -o "$tmp/out$1.bin" > "$tmp/log$1" 2>&1
  awk '{ printf "%s %.2f\n", $1, $2 + $3 }' "$tmp/time"
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
grep '^source' "$tmp/log1" | cut -d, -f1
echo "workers 1: wall $w1 s, cpu $(med "$tmp/w1" 2) s (median of $runs)"
echo "workers 2: wall $w2 s, cpu $(med "$tmp/w2" 2) s (median of $runs)"
echo "speed-up (wall 1 / wall 2): $(echo "$w1 $w2" | awk '{ printf "%.2f", $1 / $2 }')x"
for w in 1 2; do echo "workers $w, last run:"; grep '^worker' "$tmp/log$w" | sed 's/, dropped.*//'; done
cmp "$tmp/out1.bin" "$tmp/out2.bin" && echo "outputs identical"
