# Cross toolchain: Debian's aarch64 cross compiler (g++-aarch64-linux-gnu),
# target libraries from Debian's arm64 multiarch packages, test programs run
# under qemu-user. Used by .ci/cross-aarch64; README: Building for a drone computer.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)
# Libraries and pkg-config files of the target only; programs (flatc) of the host.
set(CMAKE_FIND_ROOT_PATH /usr/aarch64-linux-gnu /usr)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)   # header-only Eigen, concurrentqueue
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
set(ENV{PKG_CONFIG_LIBDIR} "/usr/lib/aarch64-linux-gnu/pkgconfig:/usr/share/pkgconfig")
# Test programs (and gtest_discover_tests) run through qemu-user, with the
# arm64 multiarch C library (libc6:arm64, /lib/ld-linux-aarch64.so.1). Not
# with `-L /usr/aarch64-linux-gnu`: that loader (libc6-arm64-cross) with the
# multiarch libc.so.6 of another version hangs in pthread_create.
find_program(EVLIFE_QEMU_AARCH64 qemu-aarch64 REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR ${EVLIFE_QEMU_AARCH64})
