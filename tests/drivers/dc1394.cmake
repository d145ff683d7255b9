# The dc1394 driver: its pure parts (bandwidth planner, settings from a config, trigger pairing)
# always; the driver itself when libdc1394-2 was found. Hardware tests skip without a camera.
fieldrig_add_test(iso_bandwidth_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/iso_bandwidth_test.cpp
                  LIBS fieldrig::drivers LABELS drivers)

find_package(yaml-cpp QUIET)
if(yaml-cpp_FOUND)
  fieldrig_add_test(dc1394_settings_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/dc1394_settings_test.cpp
                    LIBS fieldrig::drivers yaml-cpp LABELS drivers)
endif()

if(FIELDRIG_HAVE_DC1394)
  # Against the real libdc1394: the no-bus error path here, the six Grasshoppers where present.
  fieldrig_add_test(dc1394_camera_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/dc1394_camera_test.cpp
                    LIBS fieldrig::drivers LABELS drivers)

  # End to end against a fake bus: libdc1394's functions replaced at link time by
  # drivers/dc1394/testing/fake_libdc1394.cpp (the executable's definitions win).
  fieldrig_add_test(dc1394_fake_bus_test
    SOURCES ${CMAKE_CURRENT_LIST_DIR}/dc1394_fake_bus_test.cpp
            ${PROJECT_SOURCE_DIR}/drivers/dc1394/testing/fake_libdc1394.cpp
    LIBS fieldrig::drivers LABELS drivers)
  target_include_directories(dc1394_fake_bus_test PRIVATE
    ${PROJECT_SOURCE_DIR}/drivers/dc1394/testing)

  # The no-bus path and every start/stop/failure path under valgrind: no leak, no bad access.
  find_program(FIELDRIG_VALGRIND valgrind)
  if(FIELDRIG_VALGRIND)
    add_test(NAME dc1394_no_bus_memcheck
             COMMAND ${FIELDRIG_VALGRIND} --error-exitcode=99 --leak-check=full
                     --errors-for-leak-kinds=definite,indirect
                     $<TARGET_FILE:dc1394_camera_test>
                     --gtest_filter=Dc1394Camera.WithoutABus*:Dc1394Camera.Repeated*)
    add_test(NAME dc1394_fake_bus_memcheck
             COMMAND ${FIELDRIG_VALGRIND} --error-exitcode=99 --leak-check=full
                     --errors-for-leak-kinds=definite,indirect
                     $<TARGET_FILE:dc1394_fake_bus_test>)
    set_tests_properties(dc1394_no_bus_memcheck dc1394_fake_bus_memcheck
                         PROPERTIES LABELS "drivers;memcheck")
  endif()
endif()
