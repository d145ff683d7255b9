// Implemented in a later step.
#include "fieldrig/gps/serial_nmea_source.h"
