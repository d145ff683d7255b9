fieldrig_add_test(plot_view_renderer_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/plot_view_renderer_test.cpp
  LIBS fieldrig::sim_rig_render
  LABELS sim)
