# Whole-run measurement of the aravis driver against arv-fake-gv-camera-0.8 on the loopback:
# triggered frames per second and lost frames. Only when the driver is built.
if(FIELDRIG_HAVE_ARAVIS)
  find_program(FIELDRIG_ARV_FAKE_GV_CAMERA arv-fake-gv-camera-0.8)
  add_executable(aravis_fake_bench ${CMAKE_CURRENT_LIST_DIR}/aravis_fake_bench.cpp)
  target_link_libraries(aravis_fake_bench PRIVATE fieldrig::drivers)
  target_compile_definitions(aravis_fake_bench PRIVATE
    FIELDRIG_ARV_FAKE_GV_CAMERA="$<$<BOOL:${FIELDRIG_ARV_FAKE_GV_CAMERA}>:${FIELDRIG_ARV_FAKE_GV_CAMERA}>")
endif()
