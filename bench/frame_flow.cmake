add_executable(frame_handoff_bench ${CMAKE_CURRENT_LIST_DIR}/frame_handoff_bench.cpp)
target_link_libraries(frame_handoff_bench PRIVATE fieldrig::core benchmark::benchmark)
