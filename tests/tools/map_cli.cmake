# `fieldrig map generate|record` run as the built binary (record also through a socat pty).
fieldrig_add_test(map_cli_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/map_cli_test.cpp
                  LIBS fieldrig::gps GeographicLib::GeographicLib nlohmann_json::nlohmann_json
                  LABELS tools)
add_dependencies(map_cli_test fieldrig)
