fieldrig_add_test(trigger_planner_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/trigger_planner_test.cpp
  LIBS fieldrig::gps)

fieldrig_add_test(live_trigger_chain_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/live_trigger_chain_test.cpp
  LIBS fieldrig::gps fieldrig::sim)
