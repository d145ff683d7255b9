// The reader of the traits keys, shared by the whole configuration (its pipeline.traits section)
// and the traits options file alone. Internal to config/.
#pragma once

#include "fieldrig/traits/plot_traits.h"
#include "yaml_reader.h"

namespace fieldrig::config::detail {

// Reads the keys of TraitsOptions from `section` into `o`; fails naming the key on a bad value.
void readTraits(const Value& section, traits::TraitsOptions& o);

}  // namespace fieldrig::config::detail
