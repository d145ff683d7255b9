# The NMEA player: pacing, and the file, FIFO and pseudo-terminal transports.
fieldrig_add_test(nmea_player_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/nmea_player_test.cpp
                  LIBS fieldrig::sim LABELS sim)
