// Owner of the tests' precompiled header (tests/CMakeLists.txt): the headers
// come from target_precompile_headers, this file only gives CMake a source.
