# Stereo: disparity accuracy against Middlebury ground truth (table), and one FrameSet's three
# heads from raw Bayer to the fused cloud, per stage, against a straightforward pipeline.
add_executable(stereo_accuracy_bench ${CMAKE_CURRENT_LIST_DIR}/stereo_accuracy_bench.cpp)
target_link_libraries(stereo_accuracy_bench PRIVATE fieldrig::stereo)
target_compile_definitions(stereo_accuracy_bench PRIVATE
  FIELDRIG_SHARED_DATA_DIR="${FIELDRIG_SHARED_DATA_DIR}")

add_executable(stereo_pipeline_bench ${CMAKE_CURRENT_LIST_DIR}/stereo_pipeline_bench.cpp)
target_link_libraries(stereo_pipeline_bench PRIVATE fieldrig::cloud fieldrig::sim_field)
target_include_directories(stereo_pipeline_bench PRIVATE ${PROJECT_SOURCE_DIR}/tests)
