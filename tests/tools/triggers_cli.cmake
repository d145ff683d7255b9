# `fieldrig triggers`: replay contract and the live path through a real pty (socat).
fieldrig_add_test(triggers_cli_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/triggers_cli_test.cpp
  LIBS fieldrig::sim nlohmann_json::nlohmann_json
  LABELS tools)
add_dependencies(triggers_cli_test fieldrig)

fieldrig_add_test(triggers_live_cli_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/triggers_live_cli_test.cpp
  LIBS fieldrig::sim nlohmann_json::nlohmann_json
  LABELS tools virtual-device)
add_dependencies(triggers_live_cli_test fieldrig)
