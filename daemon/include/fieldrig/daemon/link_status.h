// The cameras' links as the daemon's status shows them ("packets"): GigE Vision stream packets
// resent on request and missing for good (their frames are damaged), in total and per camera.
// A count that no camera's transport has (sim, IEEE-1394) is null: not known, which is not the
// same as none lost.
#pragma once

#include <nlohmann/json.hpp>

#include "fieldrig/daemon/acquisition.h"

namespace fieldrig::daemon {

nlohmann::ordered_json linkStatusJson(const LinkSummary& link);

}  // namespace fieldrig::daemon
