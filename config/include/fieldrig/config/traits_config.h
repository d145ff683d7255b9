// Traits options alone (`fieldrig traits --config`, `fieldrig process --traits-config`): a YAML
// file with the keys of the `pipeline.traits` section at its top. JSON is YAML, so the JSON files
// of earlier versions still load (their area_method name "paper_mls_gpt" is read as "paper").
// A library of its own (fieldrig::config_traits: yaml-cpp and the traits options only), so that
// `fieldrig traits` starts without loading the cameras' and OpenCV's shared libraries.
#pragma once

#include <filesystem>

#include "fieldrig/core/result.h"
#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::config {

// The options of `file`; the error names the file, line and key path, as loadConfig's do.
core::Result<traits::TraitsOptions> loadTraitsOptions(const std::filesystem::path& file);

}  // namespace fieldrig::config
