#!/bin/sh
# `evlife process` end to end, overlapped (the default: input decoded ahead,
# output written behind, each on a thread of its own) against --one-thread,
# on one synthetic recording (`evlife synth --scene mixed`, 346x260, HDF5
# input) to each output format; runs alternate, median of N each. Prints
# per format the wall seconds of both, their ratio, and whether the outputs
# are identical byte for byte. Wall times need an otherwise idle machine.
#   bench/bench_process.sh [build/engine/evlife] [runs] [seconds of scene]
set -eu
cli=${1:-build/engine/evlife}
runs=${2:-5}
seconds=${3:-10}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$cli" synth --scene mixed --sensor 346x260 --duration "$seconds" -o "$tmp/scene.h5" --quiet
events=$("$cli" info "$tmp/scene.h5" 2>/dev/null | sed -n 's/^events *\([0-9,]*\).*/\1/p')
echo "scene: ${events:-?} events, ${seconds} s of 346x260 (evlife synth --scene mixed), HDF5"
wall() {  # mode ext -> wall seconds
  rm -f "$tmp/out.$2"
  flag=""
  [ "$1" = one ] && flag="--one-thread"
  /usr/bin/time -f '%e' -o "$tmp/time" "$cli" process "$tmp/scene.h5" -o "$tmp/out.$2" -q $flag
  cp "$tmp/out.$2" "$tmp/last_$1.$2"
  cat "$tmp/time"
}
med() { sort -n "$1" | sed -n "$(( (runs + 1) / 2 ))p"; }
printf '%-6s %14s %14s %8s  %s\n' output overlapped_s one_thread_s ratio same_bytes
for ext in ${FORMATS:-bin csv h5}; do
  : > "$tmp/over"; : > "$tmp/one"
  i=0
  while [ "$i" -lt "$runs" ]; do
    wall over "$ext" >> "$tmp/over"
    wall one "$ext" >> "$tmp/one"
    i=$((i + 1))
  done
  same=no
  cmp -s "$tmp/last_over.$ext" "$tmp/last_one.$ext" && same=yes
  o=$(med "$tmp/over"); s=$(med "$tmp/one")
  printf '%-6s %14s %14s %8.2f  %s\n' "$ext" "$o" "$s" "$(echo "$s / $o" | bc -l)" "$same"
done
