# The aravis driver against Aravis' own fakes: the in-process Fake interface and
# arv-fake-gv-camera-0.8 speaking GigE Vision over the loopback. Only when the driver is built.
if(FIELDRIG_HAVE_ARAVIS)
  find_program(FIELDRIG_ARV_FAKE_GV_CAMERA arv-fake-gv-camera-0.8)
  fieldrig_add_test(aravis_camera_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/aravis_camera_test.cpp
                    LIBS fieldrig::drivers LABELS drivers)
  # Empty when aravis-tools is missing: the GigE Vision tests then skip.
  target_compile_definitions(aravis_camera_test PRIVATE
    FIELDRIG_ARV_FAKE_GV_CAMERA="$<$<BOOL:${FIELDRIG_ARV_FAKE_GV_CAMERA}>:${FIELDRIG_ARV_FAKE_GV_CAMERA}>")
endif()
