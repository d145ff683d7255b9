# Whole-run benchmark of the plot traits on synthetic plots with known truth: a table per plot
# (error vs truth for height, width, VVI, area, VAI; the truth's own spread under voxel-grid
# shifts) and the timing of all traits on a 75,905-point plot against the paper's PCL pipeline
# (MLS + greedy projection triangulation) run on the same cloud in the same run.
add_executable(traits_bench ${CMAKE_CURRENT_LIST_DIR}/traits_bench.cpp)
target_link_libraries(traits_bench PRIVATE fieldrig::traits fieldrig::sim_plot_truth)
target_include_directories(traits_bench PRIVATE ${PROJECT_SOURCE_DIR}/tests)
