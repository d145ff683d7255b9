add_executable(trigger_planner_bench ${CMAKE_CURRENT_LIST_DIR}/trigger_planner_bench.cpp)
target_link_libraries(trigger_planner_bench PRIVATE fieldrig::gps benchmark::benchmark)

# Whole-run benchmark: prints the trigger accuracy table (1, 2, 3 m/s) against a naive baseline.
add_executable(trigger_accuracy_bench ${CMAKE_CURRENT_LIST_DIR}/trigger_accuracy_bench.cpp)
target_link_libraries(trigger_accuracy_bench PRIVATE fieldrig::sim)
