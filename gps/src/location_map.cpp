#include "fieldrig/gps/location_map.h"
