// Implemented in a later step.
#include "fieldrig/gps/field_plan.h"
