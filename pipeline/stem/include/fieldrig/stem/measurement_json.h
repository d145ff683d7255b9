// A stem measurement as one JSON object: what `fieldrig stem --json` prints and what the stem
// page's API answers. Values that the status leaves undefined are null.
#pragma once

#include <nlohmann/json.hpp>

#include "fieldrig/stem/stem_measurer.h"

namespace fieldrig::stem {

nlohmann::ordered_json toJson(const StemMeasurement& m);

}  // namespace fieldrig::stem
