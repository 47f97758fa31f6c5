# The MCAP files of test_io_mcap (and bench_ros_payloads' mcap case), written
# at build time by the test-only writer make_mcap.py from the shared rosbag2
# bags into <build>/tests/data/mcap (about 10 MB, 1 s). Debian:
# python3-zstandard python3-lz4.
set(EVLIFE_MCAP_TEST_DIR ${PROJECT_BINARY_DIR}/tests/data/mcap)
set(outputs "")
foreach(bag evt3 libcaer mono)
  foreach(how none zstd lz4)
    list(APPEND outputs ${EVLIFE_MCAP_TEST_DIR}/${bag}_${how}.mcap)
  endforeach()
endforeach()
foreach(f mono_unchunked mono_ros1 evt3_reversed libcaer_swapped)
  list(APPEND outputs ${EVLIFE_MCAP_TEST_DIR}/${f}.mcap)
endforeach()
foreach(bag evt3 mono)
  foreach(f zstd_frames lz4_frames zstd_datacrc zstd_summarycrc)
    list(APPEND outputs ${EVLIFE_MCAP_TEST_DIR}/${bag}_${f}.mcap)
  endforeach()
endforeach()
add_custom_command(
  OUTPUT ${outputs}
  COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/make_mcap.py ${EVLIFE_MCAP_TEST_DIR} ${EVLIFE_SHARED_DATA_DIR}
  DEPENDS ${CMAKE_CURRENT_LIST_DIR}/make_mcap.py ${CMAKE_CURRENT_LIST_DIR}/../ros_mono_dvs.py
  COMMENT "make_mcap.py: MCAP test files")
add_custom_target(evlife_mcap_test_files DEPENDS ${outputs})
if(TARGET test_io_mcap)
  add_dependencies(test_io_mcap evlife_mcap_test_files)
  target_compile_definitions(test_io_mcap PRIVATE EVLIFE_MCAP_TEST_DIR="${EVLIFE_MCAP_TEST_DIR}")
endif()
