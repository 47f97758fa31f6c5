# DVS128 over USB: the real libusb path against umockdev's
# in-process usbdevfs emulation. Included from tests/CMakeLists.txt.
# Tests using the emulator must run under `umockdev-wrapper` (an LD_PRELOAD
# shim, no root needed): they get it as their launcher, for test discovery and
# for ctest. Debian: umockdev libumockdev-dev.
find_package(PkgConfig REQUIRED)
pkg_check_modules(UMOCKDEV IMPORTED_TARGET umockdev-1.0)
find_program(EVLIFE_UMOCKDEV_WRAPPER umockdev-wrapper)

evlife_add_test(test_dvs128_decoder LIBS evlife::io)

if(UMOCKDEV_FOUND AND EVLIFE_UMOCKDEV_WRAPPER)
  add_library(evlife_dvs128_emulator STATIC ${CMAKE_CURRENT_LIST_DIR}/dvs128_emulator.cpp)
  target_include_directories(evlife_dvs128_emulator PUBLIC ${CMAKE_CURRENT_LIST_DIR})
  target_link_libraries(evlife_dvs128_emulator PUBLIC PkgConfig::UMOCKDEV PRIVATE evlife_warnings)
  target_compile_definitions(evlife_dvs128_emulator PRIVATE
    EVLIFE_DVS128_FIXTURE="${CMAKE_CURRENT_LIST_DIR}/dvs128.umockdev")

  # The launcher (umockdev_launcher.sh: umockdev-wrapper plus sanitizer
  # settings) is picked up by gtest_discover_tests, for discovery and ctest.
  set(CMAKE_CROSSCOMPILING_EMULATOR /bin/sh ${CMAKE_CURRENT_LIST_DIR}/umockdev_launcher.sh)
  evlife_add_test(test_dvs128_device LIBS evlife::io evlife_dvs128_emulator)
  if(TARGET evlife_engine)
    evlife_add_test(test_dvs128_source LIBS evlife::engine evlife::io evlife_dvs128_emulator)
  endif()
  evlife_add_test(test_dvs128_cli LIBS evlife::io evlife_dvs128_emulator)
  unset(CMAKE_CROSSCOMPILING_EMULATOR)
else()
  message(WARNING "umockdev (Debian: umockdev libumockdev-dev) not found: "
                  "the DVS128 USB tests are not built")
endif()

# Latency bench (needs the emulator, so it lives here rather than in bench/):
#   umockdev-wrapper ./tests/bench_dvs128_latency
if(EVLIFE_BUILD_BENCH AND TARGET evlife_dvs128_emulator AND TARGET evlife_engine)
  find_package(benchmark REQUIRED)
  add_executable(bench_dvs128_latency ${CMAKE_CURRENT_LIST_DIR}/bench_dvs128_latency.cpp)
  target_link_libraries(bench_dvs128_latency PRIVATE evlife::engine evlife::io
                        evlife_dvs128_emulator benchmark::benchmark evlife_warnings)
endif()
