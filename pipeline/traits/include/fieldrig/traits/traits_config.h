// TraitsOptions from a JSON file (the `--config` of `fieldrig traits`): every key optional, an
// unknown or ill-typed key is an error naming the file and the key.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "fieldrig/core/result.h"
#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::traits {

core::Result<TraitsOptions> traitsOptionsFromJson(const nlohmann::json& json,
                                                  const std::string& origin,
                                                  TraitsOptions options = {});
core::Result<TraitsOptions> loadTraitsOptions(const std::string& path);

}  // namespace fieldrig::traits
