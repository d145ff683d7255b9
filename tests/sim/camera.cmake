# The sim camera driver (sim/camera): one test file per class (the frame sources, fault
# injection, the driver and its README's example configuration).
fieldrig_add_test(sim_camera_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_pattern_source_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/session_replay_source_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/fault_injector_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/sim_camera_test.cpp
  LIBS fieldrig::sim_camera fieldrig::recording fieldrig::config LABELS sim)
# Records with the generated sim rig (daemon::Acquisition, and the CLI), replays with session=DIR.
fieldrig_add_test(sim_replay_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/sim_replay_test.cpp
  LIBS fieldrig::sim_camera fieldrig::recording fieldrig::daemon nlohmann_json::nlohmann_json
  LABELS sim)
add_dependencies(sim_replay_test fieldrig)  # its CLI test runs the built binary
