// Implemented in a later step.
#include "fieldrig/gps/trigger_planner.h"
