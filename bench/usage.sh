# Sourced first by the bench scripts: -h or --help prints the script's
# header comment (its usage) and exits; before, each took --help for its
# first argument (an evlife binary, or a build dir that build_cost.sh empties).
case ${1:-} in
  -h | --help)
    sed -n '2,/^[^#]/{/^#/s/^# \{0,1\}//p;}' "$0"
    exit 0
    ;;
esac

# The scripts' checks of their arguments, before any work: exit 2, named.
# need_executable PATH: the evlife binary the script times.
need_executable() {
  if [ ! -f "$1" ] || [ ! -x "$1" ]; then
    echo "$(basename "$0"): $1: not an executable file (an evlife build: build/engine/evlife)" >&2
    exit 2
  fi
}
# need_count NAME VALUE: a whole number of runs, at least 1.
need_count() {
  case $2 in
    '' | *[!0-9]*) ;;
    *) [ "$2" -ge 1 ] && return 0 ;;
  esac
  echo "$(basename "$0"): $1 must be a whole number, at least 1 (got '$2')" >&2
  exit 2
}
# need_time: GNU time, whose -f/-o the scripts read (`time` is a shell keyword
# without them; Debian's package `time`, in .ci/debian-packages).
need_time() {
  if [ ! -x /usr/bin/time ]; then
    echo "$(basename "$0"): needs /usr/bin/time (apt-get install time)" >&2
    exit 2
  fi
}
