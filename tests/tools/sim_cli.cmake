fieldrig_add_test(sim_cli_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/sim_cli_test.cpp
  LIBS fieldrig::gps nlohmann_json::nlohmann_json
  LABELS tools)
add_dependencies(sim_cli_test fieldrig)
