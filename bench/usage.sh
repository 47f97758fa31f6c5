# Sourced first by the bench scripts: -h or --help prints the script's
# header comment (its usage) and exits; before, each took --help for its
# first argument (an evlife binary, or a build dir that build_cost.sh empties).
case ${1:-} in
  -h | --help)
    sed -n '2,/^[^#]/{/^#/s/^# \{0,1\}//p;}' "$0"
    exit 0
    ;;
esac
