#!/bin/sh
# Runs a DVS128 test under umockdev-wrapper (LD_PRELOAD of umockdev's shim:
# no root needed). ctest uses it as the tests' launcher (dvs128_tests.cmake).
# Sanitizer builds: ASan must accept the preload coming first; TSan must not
# report GLib/umockdev internals (uninstrumented, see tsan_glib.supp). The
# settings are appended to the caller's options and inherited by children
# (the evlife CLI the CLI tests start).
here=$(dirname "$0")
ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}verify_asan_link_order=0"
TSAN_OPTIONS="${TSAN_OPTIONS:+$TSAN_OPTIONS:}suppressions=$here/tsan_glib.supp"
export ASAN_OPTIONS TSAN_OPTIONS
exec umockdev-wrapper "$@"
