# A short libFuzzer run of the NMEA parser (scripts/fuzz-nmea.sh builds it with clang++ itself).
# Skipped (exit 77) where clang++ or its fuzzer runtime is not installed.
add_test(NAME nmea_parser_fuzz
  COMMAND ${PROJECT_SOURCE_DIR}/scripts/fuzz-nmea.sh 15)
set_tests_properties(nmea_parser_fuzz PROPERTIES
  LABELS fuzz
  SKIP_RETURN_CODE 77
  TIMEOUT 300
  ENVIRONMENT "FIELDRIG_SHARED_DATA_DIR=${FIELDRIG_SHARED_DATA_DIR}")
