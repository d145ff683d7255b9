# The fused cloud from a synthetic calibrated rig; rig.yml; PLY.
fieldrig_add_test(cloud_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/cloud_test.cpp
                  LIBS fieldrig::cloud LABELS cloud)

# `fieldrig cloud` as the built binary: session and file input, partial clouds, bad calibration.
fieldrig_add_test(cloud_cli_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/cloud_cli_test.cpp
                  LIBS fieldrig::cloud fieldrig::recording nlohmann_json::nlohmann_json
                  LABELS cloud)
add_dependencies(cloud_cli_test fieldrig)
