# NMEA parser and fix assembler: unit tests and the replay of gpsd's regression logs.
fieldrig_add_test(nmea_parser_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/nmea_parser_test.cpp
  LIBS fieldrig::nmea
  LABELS gps)
fieldrig_add_test(fix_assembler_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/fix_assembler_test.cpp
  LIBS fieldrig::nmea
  LABELS gps)
fieldrig_add_test(gpsd_regression_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/gpsd_regression_test.cpp
  LIBS fieldrig::nmea nlohmann_json::nlohmann_json
  LABELS gps)
