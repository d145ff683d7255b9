// TraitsOptions::validate: the defaults pass; every number outside the range the steps are meant
// for (NaN, infinity, negative, absurdly small or large) is named with its key and range.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::traits {
namespace {

TEST(TraitsOptionsValidate, DefaultsAreValid) {
  const auto problem = TraitsOptions{}.validate();
  EXPECT_FALSE(problem.has_value()) << problem->key << ": " << problem->message;
}

struct BadOption {
  std::string key;
  std::function<void(TraitsOptions&)> set;
  std::string range;  // what the message must say
};

TEST(TraitsOptionsValidate, NamesTheKeyAndTheRange) {
  constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const std::vector<BadOption> cases = {
      {"depth_map_cell_m", [](TraitsOptions& o) { o.depth_map_cell_m = 1e-9; }, "[0.001, 1]"},
      {"depth_map_cell_m", [&](TraitsOptions& o) { o.depth_map_cell_m = kNan; }, "[0.001, 1]"},
      {"slices", [](TraitsOptions& o) { o.slices = -1; }, "[0, 1000]"},
      {"slices", [](TraitsOptions& o) { o.slices = 2'000'000'000; }, "[0, 1000]"},
      {"row_length_m", [](TraitsOptions& o) { o.row_length_m = -1; }, "[0.01, 100]"},
      {"row_length_m", [&](TraitsOptions& o) { o.row_length_m = kInf; }, "[0.01, 100]"},
      {"icp_iterations", [](TraitsOptions& o) { o.icp_iterations = 0; }, "[1, 1000]"},
      {"icp_iterations", [](TraitsOptions& o) { o.icp_iterations = 100'000'000; }, "[1, 1000]"},
      {"outlier_mean_k", [](TraitsOptions& o) { o.outlier_mean_k = 0; }, "[1, 1000]"},
      {"outlier_stddev_mul", [&](TraitsOptions& o) { o.outlier_stddev_mul = kNan; }, "[0, 100]"},
      {"outlier_min_neighbours", [](TraitsOptions& o) { o.outlier_min_neighbours = 27; },
       "[0, 26]"},
      {"voxel_leaf_m", [](TraitsOptions& o) { o.voxel_leaf_m = 0; }, "[0.001, 1]"},
      {"min_piece_voxels", [](TraitsOptions& o) { o.min_piece_voxels = -1; }, "[0, 1000000]"},
      {"alpha", [](TraitsOptions& o) { o.alpha = 1; }, "[0, 1)"},
      {"row_base_band_m", [](TraitsOptions& o) { o.row_base_band_m = -0.01; }, "[0, 1]"},
      {"row_base_band_m", [&](TraitsOptions& o) { o.row_base_band_m = kNan; }, "[0, 1]"},
      {"slice_width_quantile", [](TraitsOptions& o) { o.slice_width_quantile = 0.3; }, "[0, 0.25]"},
      {"slice_width_quantile", [](TraitsOptions& o) { o.slice_width_quantile = -0.01; },
       "[0, 0.25]"},
      {"width_band_m", [](TraitsOptions& o) { o.width_band_m = -0.1; }, "[0, 100]"},
      {"gpt_max_neighbors", [](TraitsOptions& o) { o.gpt_max_neighbors = -5; }, "[1, 10000]"},
      {"camera_to_plot", [&](TraitsOptions& o) { o.camera_to_plot(1, 2) = kNan; }, "[-1000, 1000]"},
      {"crop_z_min_m", [](TraitsOptions& o) { o.crop_z_min_m = 2.0; }, "crop_z_max_m (1.7)"},
  };
  for (const BadOption& c : cases) {
    TraitsOptions options;
    c.set(options);
    const auto problem = options.validate();
    ASSERT_TRUE(problem.has_value()) << c.key << " " << c.range;
    EXPECT_EQ(problem->key, c.key);
    EXPECT_NE(problem->message.find(c.range), std::string::npos) << problem->message;
  }
}

}  // namespace
}  // namespace fieldrig::traits
