# `fieldrig nmea decode`: the CLI contract, checked by running the built binary.
fieldrig_add_test(nmea_decode_cli_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/nmea_decode_cli_test.cpp
  LIBS fieldrig::nmea nlohmann_json::nlohmann_json
  LABELS tools)
add_dependencies(nmea_decode_cli_test fieldrig)
