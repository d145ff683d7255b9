# The serial source against a real pseudo-terminal pair made by socat (a virtual-device test:
# it needs /usr/bin/socat and fails, rather than skips, without it).
fieldrig_add_test(gps_serial_test SOURCES serial_nmea_source_test.cpp LIBS fieldrig::gps
                  LABELS virtual-device)
