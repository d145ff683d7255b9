// libFuzzer target for config::loadTraitsOptions, the traits options file of `fieldrig traits
// --config` and `fieldrig process --traits-config` (YAML, or the JSON of earlier versions).
//
// Besides crashes and sanitizer reports: an error names the file; options that load are inside
// the ranges TraitsOptions::validate() states (no NaN, no 1e-9 m cell, no two billion slices),
// with a depth crop that is not empty and a slice count the traits can allocate.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fieldrig/config/config.h"
#include "fuzz_support.h"

namespace {

using fieldrig::fuzz::check;
using fieldrig::fuzz::startsWith;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // The `pipeline.traits` section of config/fieldrigd.yaml, the JSON of earlier versions, and a
  // key of every kind.
  fieldrig::fuzz::writeSeed("fieldrigd",
                            "crop_z_max_m: 1.7\nrow_length_m: 1.5\n"
                            "intra_row_spacing_m: 0.15\narea_method: depth_map\n");
  fieldrig::fuzz::writeSeed("json",
                            "{\"voxel_leaf_m\": 0.01, \"area_method\": \"paper_mls_gpt\", "
                            "\"slices\": 20, \"outlier_method\": \"statistical\"}\n");
  fieldrig::fuzz::writeSeed(
      "kinds",
      "camera_to_plot: [[0, -1, 0], [1, 0, 0], [0, 0, 1]]\noutlier_mean_k: 50\n"
      "outlier_min_neighbours: 2\ncrop_z_min_m: 0.1\nmax_ground_tilt_deg: 15\n"
      "min_plant_points: 50\nalpha: 0.3\ndepth_map_cell_m: 0.01\ndepth_map_min_fill: 0.6\n"
      "gpt_max_neighbors: 100\nicp_iterations: 10\n");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  static const fieldrig::fuzz::FuzzFolder folder("traits_options");
  const auto file = folder.write("traits.yaml", {reinterpret_cast<const char*>(bytes), size});
  const auto options = fieldrig::config::loadTraitsOptions(file);
  if (!options) {
    check(startsWith(options.error().message, file.string()),
          "an error that does not name the file");
    return 0;
  }
  check(!options->validate().has_value(), "options out of their ranges were accepted");
  check(options->crop_z_min_m < options->crop_z_max_m, "an empty depth crop was accepted");
  check(options->camera_to_plot.allFinite(), "a camera-to-plot matrix that is not finite");
  const int slices = fieldrig::traits::sliceCount(*options);
  check(slices >= 1 && slices <= 1000, "a slice count outside what the traits can allocate");
  return 0;
}
