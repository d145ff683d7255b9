# Imaging-location maps: the CSV format and maps generated from a field plan.
fieldrig_add_test(location_map_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/location_map_test.cpp
                  LIBS fieldrig::gps LABELS gps)
fieldrig_add_test(field_plan_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/field_plan_test.cpp
                  LIBS fieldrig::gps GeographicLib::GeographicLib LABELS gps)
