# The stereo library: preprocessing, matcher, scoring, PFM, head pipeline errors (unit);
# calibration on OpenCV's sample set and synthetic head-to-head boards; accuracy against
# Middlebury ground truth next to default OpenCV SGBM.
fieldrig_add_test(stereo_calibrate_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/stereo_calibrate_test.cpp
                  LIBS fieldrig::stereo LABELS stereo)
fieldrig_add_test(stereo_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/stereo_test.cpp
                  LIBS fieldrig::stereo LABELS stereo)
fieldrig_add_test(stereo_accuracy_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/stereo_accuracy_test.cpp
                  LIBS fieldrig::stereo LABELS stereo)

# `fieldrig calibrate` and `fieldrig disparity` as the built binary.
fieldrig_add_test(stereo_cli_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/stereo_cli_test.cpp
                  LIBS fieldrig::stereo nlohmann_json::nlohmann_json LABELS stereo)
add_dependencies(stereo_cli_test fieldrig)
