fieldrig_add_test(process_cli_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/process_cli_test.cpp
  LIBS nlohmann_json::nlohmann_json
  LABELS tools pipeline)
add_dependencies(process_cli_test fieldrig)
