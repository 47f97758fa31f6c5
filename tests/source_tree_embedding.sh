#!/bin/sh
# The README's source-tree recipe (add_subdirectory(evlife), algo only) leaves
# the outer project's build type alone: evlife set it to Release when none was
# given, so the outer project's own code lost its asserts (-O3 -DNDEBUG).
# Usage: source_tree_embedding.sh CMAKE SOURCE_DIR SCRATCH NINJA
set -eu
cmake=$1 source=$2 scratch=$3 ninja=$4
fail() { echo "source_tree_embedding: $*" >&2; exit 1; }
rm -rf "$scratch"
mkdir -p "$scratch/app"
cd "$scratch"
cat >app/CMakeLists.txt <<CMAKE
cmake_minimum_required(VERSION 3.20)
project(my_app CXX)
set(CMAKE_CXX_STANDARD 20)
set(EVLIFE_BUILD_APPS OFF)
add_subdirectory("$source" evlife)
add_executable(my_app main.cpp)
target_link_libraries(my_app PRIVATE evlife::algo)
CMAKE
echo 'int main() { return 0; }' >app/main.cpp
"$cmake" -S app -B build -G Ninja -DCMAKE_MAKE_PROGRAM="$ninja" >configure.log 2>&1 || fail "configure failed: $(tail -5 configure.log)"
type=$(sed -n 's/^CMAKE_BUILD_TYPE:STRING=//p' build/CMakeCache.txt)
[ -z "$type" ] || fail "the outer project's build type became '$type'"
# The embedding example is evlife's own check, not built by the outer project's default target.
"$ninja" -C build -t commands all >plan.log 2>&1 || fail "no build plan: $(tail -3 plan.log)"
grep -q "main.cpp" plan.log || fail "the plan does not build the outer project: $(tail -3 plan.log)"
! grep -q "minimal_embedding" plan.log || fail "the outer project's build compiles evlife's example"
echo "source_tree_embedding: ok"
