# Plot traits: the trait math on hand-made geometry, the pipeline against synthetic truth, bad
# input statuses, the CSV/GeoJSON report, and the `fieldrig traits` CLI contract.
fieldrig_add_test(traits_math_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/traits_math_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/plot_report_test.cpp
  LIBS fieldrig::traits
  LABELS traits)
fieldrig_add_test(traits_truth_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/traits_truth_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/traits_bad_input_test.cpp
  LIBS fieldrig::traits fieldrig::sim_plot_truth
  LABELS traits)
fieldrig_add_test(traits_cli_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/traits_cli_test.cpp
  LIBS fieldrig::traits nlohmann_json::nlohmann_json
  LABELS traits cli)
add_dependencies(traits_cli_test fieldrig)
