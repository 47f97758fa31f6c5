#!/bin/sh
# `cmake --install` as a packager or a flight-software build uses it:
#  - component cli: the tool runs from any prefix and from a copied tree, reads
#    its own share/evlife/evlife.yaml and loads its own libevlife_media.so;
#  - component algo: an outside project builds the embedding example against
#    the installed evlife::algo, with find_package(evlife) and with pkg-config.
# Usage: install_tree.sh CMAKE BUILD_DIR SOURCE_DIR SCRATCH CXX
set -eu
cmake=$1 build=$2 source=$3 scratch=$4 cxx=$5
fail() { echo "install_tree: $*" >&2; exit 1; }

rm -rf "$scratch"
mkdir -p "$scratch"
cd "$scratch"

# ---- the tool ----
"$cmake" --install "$build" --component cli --prefix "$scratch/cli" >/dev/null
tool=$scratch/cli/bin/evlife
[ -x "$tool" ] || fail "no bin/evlife installed"
for f in evlife.yaml dim-light.yaml faint-texture.yaml dvs128_biases.yaml 99-evlife-dvs128.rules; do
  [ -f "$scratch/cli/share/evlife/$f" ] || fail "share/evlife/$f not installed"
done
# A copied tree (another prefix, a DESTDIR staged to a drone's image) works alike.
cp -a "$scratch/cli" "$scratch/moved"
tool=$scratch/moved/bin/evlife
"$tool" --help >help.txt
grep -q "without --config: $scratch/moved/share/evlife/evlife.yaml" help.txt ||
  fail "the moved tool does not name its own configuration: $(grep -- '--config' help.txt)"
"$tool" process --print-config >config.txt 2>&1
grep -q "$scratch/moved/share/evlife/evlife.yaml" config.txt ||
  fail "the moved tool does not read its own configuration: $(head -3 config.txt)"
# Its own media plugin, not the build tree's (which still exists): the loader's log names it.
"$tool" synth --duration 20ms -o scene.txt >/dev/null 2>&1 || fail "synth failed"
LD_DEBUG=files "$tool" render scene.txt -o frame.png --at 15ms >/dev/null 2>render.log ||
  fail "render failed: $(grep -v '^ *[0-9]*:' render.log | tail -3)"
[ -s frame.png ] || fail "render wrote no frame"
grep -q "file=$scratch/moved/lib[^ ]*/libevlife_media.so" render.log ||
  fail "the moved tool did not load its own plugin: $(grep libevlife_media render.log | head -2)"

# ---- the estimator for an outside build ----
"$cmake" --install "$build" --component algo --prefix "$scratch/algo" >/dev/null
[ -f "$scratch/algo/include/evlife/algo/lifetime_estimator.h" ] || fail "algo headers not installed"
[ ! -e "$scratch/algo/bin" ] || fail "component algo installed a program"
mkdir app
cat >app/CMakeLists.txt <<EOF
cmake_minimum_required(VERSION 3.20)
project(embedding CXX)
set(CMAKE_CXX_STANDARD 20)
find_package(evlife 0.1 CONFIG REQUIRED)
add_executable(embedding "$source/algo/example/minimal_embedding.cpp")
target_link_libraries(embedding PRIVATE evlife::algo)
EOF
"$cmake" -S app -B app/build -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_PREFIX_PATH="$scratch/algo" \
  >app.log 2>&1 || fail "find_package(evlife) failed: $(tail -5 app.log)"
"$cmake" --build app/build >>app.log 2>&1 || fail "the example did not build: $(tail -5 app.log)"
app/build/embedding >/dev/null || fail "the example built with find_package failed"
pc_dir=$(dirname "$(find "$scratch/algo" -name evlife-algo.pc)")
flags=$(PKG_CONFIG_PATH=$pc_dir pkg-config --cflags --libs evlife-algo) || fail "pkg-config evlife-algo failed"
# Built with exceptions: nothing says otherwise (a -fno-exceptions build adds -DEVLIFE_ALGO_NO_EXCEPTIONS=1).
case $flags in *EVLIFE_ALGO_NO_EXCEPTIONS*) fail "pkg-config says a library with exceptions has none: $flags" ;; esac
# shellcheck disable=SC2086  # the flags are words
"$cxx" -std=c++20 "$source/algo/example/minimal_embedding.cpp" $flags -o embedding_pc ||
  fail "the example did not build with pkg-config's flags: $flags"
./embedding_pc >/dev/null || fail "the example built with pkg-config failed"
echo "install_tree: ok"
