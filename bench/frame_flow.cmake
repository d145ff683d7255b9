add_executable(frame_handoff_bench ${CMAKE_CURRENT_LIST_DIR}/frame_handoff_bench.cpp)
target_link_libraries(frame_handoff_bench PRIVATE fieldrig::core benchmark::benchmark)

# Whole-run benchmark: trigger → FrameSet latency (rig sink, acquisition consumer; p50/p99) and
# the idle CPU of a started rig and acquisition, six sim cameras. Prints a Markdown table.
add_executable(trigger_to_record_bench ${CMAKE_CURRENT_LIST_DIR}/trigger_to_record_bench.cpp)
target_link_libraries(trigger_to_record_bench PRIVATE fieldrig::daemon fieldrig::drivers
                                                      fieldrig::sim_camera)
target_include_directories(trigger_to_record_bench PRIVATE ${PROJECT_SOURCE_DIR}/tests)
