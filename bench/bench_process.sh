#!/bin/sh
# `evlife process` and `evlife convert` end to end, overlapped (the default:
# input decoded ahead and, for process, output written behind, each on a
# thread of its own) against --one-thread, on one synthetic recording
# (`evlife synth --scene mixed`, 346x260): process from HDF5 to each output
# format, convert HDF5 -> text and text -> HDF5. Runs alternate, median of N
# each. Prints per row the wall seconds of both, their ratio, and whether the
# outputs are identical byte for byte. Wall times need an otherwise idle machine.
#   bench/bench_process.sh [build/engine/evlife] [runs] [seconds of scene]
#   FORMATS="bin csv h5" CONVERTS="h5:txt txt:h5" select rows ("" skips them).
. "$(dirname "$0")/usage.sh"
set -eu
cli=${1:-build/engine/evlife}
runs=${2:-5}
seconds=${3:-10}
need_executable "$cli"
need_count runs "$runs"
need_time
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$cli" synth --scene mixed --sensor 346x260 --duration "$seconds" -o "$tmp/scene.h5" --quiet
events=$("$cli" info "$tmp/scene.h5" 2>/dev/null | sed -n 's/^events *\([0-9,]*\).*/\1/p')
echo "scene: ${events:-?} events, ${seconds} s of 346x260 (evlife synth --scene mixed)"
wall() {  # mode command input ext -> wall seconds
  rm -f "$tmp/out.$4"
  flag=""
  [ "$1" = one ] && flag="--one-thread"
  /usr/bin/time -f '%e' -o "$tmp/time" "$cli" "$2" "$tmp/$3" -o "$tmp/out.$4" -q $flag
  cp "$tmp/out.$4" "$tmp/last_$1.$4"
  cat "$tmp/time"
}
med() { sort -n "$1" | sed -n "$(( (runs + 1) / 2 ))p"; }
row() {  # command input ext
  : > "$tmp/over"; : > "$tmp/one"
  i=0
  while [ "$i" -lt "$runs" ]; do
    wall over "$1" "$2" "$3" >> "$tmp/over"
    wall one "$1" "$2" "$3" >> "$tmp/one"
    i=$((i + 1))
  done
  same=no
  cmp -s "$tmp/last_over.$3" "$tmp/last_one.$3" && same=yes
  o=$(med "$tmp/over"); s=$(med "$tmp/one")
  printf '%-22s %14s %14s %8.2f  %s\n' "$1 $2 -> .$3" "$o" "$s" "$(echo "$s $o" | awk '{ printf "%.4f", $1 / $2 }')" "$same"
}
printf '%-22s %14s %14s %8s  %s\n' run overlapped_s one_thread_s ratio same_bytes
for ext in ${FORMATS-bin csv h5}; do
  row process scene.h5 "$ext"
done
for pair in ${CONVERTS-h5:txt txt:h5}; do
  from=${pair%%:*}; to=${pair##*:}
  [ -f "$tmp/scene.$from" ] || "$cli" convert "$tmp/scene.h5" "$tmp/scene.$from" -q
  row convert "scene.$from" "$to"
done
