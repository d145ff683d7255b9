# NMEA parser throughput (sentences/s) against a straightforward getline/split/stod baseline.
add_executable(nmea_parser_bench ${CMAKE_CURRENT_SOURCE_DIR}/nmea_parser_bench.cpp)
target_link_libraries(nmea_parser_bench PRIVATE fieldrig::nmea benchmark::benchmark)
