# Whole-run benchmark of the session writer: six 1624×1224 RAW8 frames per set, per fsync policy;
# prints sets/s, MB/s and CPU time per set. Writes at most ~1.8 GB to a temporary folder.
add_executable(recording_bench ${CMAKE_CURRENT_LIST_DIR}/recording_bench.cpp)
find_package(ZLIB REQUIRED)
target_link_libraries(recording_bench PRIVATE fieldrig::recording ZLIB::ZLIB)
target_include_directories(recording_bench PRIVATE ${PROJECT_SOURCE_DIR}/tests)
