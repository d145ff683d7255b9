# The sim camera driver (sim/camera): one test per frame source, fault injection, the driver and
# its README's example configuration.
fieldrig_add_test(test_pattern_source_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_pattern_source_test.cpp
  LIBS fieldrig::sim_camera LABELS sim)
fieldrig_add_test(session_replay_source_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/session_replay_source_test.cpp
  LIBS fieldrig::sim_camera fieldrig::recording LABELS sim)
fieldrig_add_test(fault_injector_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/fault_injector_test.cpp
  LIBS fieldrig::sim_camera LABELS sim)
fieldrig_add_test(sim_camera_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/sim_camera_test.cpp
  LIBS fieldrig::sim_camera fieldrig::config LABELS sim)
