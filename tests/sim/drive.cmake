fieldrig_add_test(drive_simulator_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/drive_simulator_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/trigger_accuracy_test.cpp
  LIBS fieldrig::sim)
