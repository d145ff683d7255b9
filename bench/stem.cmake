# The stem measurement's accuracy campaign on rendered cylinders (a table per method: MAE, bias,
# r, SD of four repeats, refusals, time per measurement) and its timing (Google Benchmark).
add_executable(stem_accuracy_bench ${CMAKE_CURRENT_LIST_DIR}/stem_accuracy_bench.cpp)
target_link_libraries(stem_accuracy_bench PRIVATE fieldrig::stem fieldrig::sim_render)
target_include_directories(stem_accuracy_bench PRIVATE ${PROJECT_SOURCE_DIR}/tests)

add_executable(stem_timing_bench ${CMAKE_CURRENT_LIST_DIR}/stem_timing_bench.cpp)
target_link_libraries(stem_timing_bench PRIVATE fieldrig::stem fieldrig::sim_render
                                                benchmark::benchmark)
target_include_directories(stem_timing_bench PRIVATE ${PROJECT_SOURCE_DIR}/tests)
