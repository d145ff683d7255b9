// Time of one stem measurement (clicks → diameter: rectification of the points and of the two
// regions, sub-pixel edges, NCC over the disparity range, cylinder model) on a rendered
// 1624×1224 pair, against the same measurement with the clicks at face value (no edge search).
// Issue 6's target: ≤ 20 ms.
#include <benchmark/benchmark.h>

#include <random>

#include "support/stem_campaign.h"

namespace {

using namespace fieldrig;

void measureStem(benchmark::State& state, double diameter_mm, double depth_m, bool refine) {
  auto cases = testing_support::makeStemCases({diameter_mm}, {depth_m}, 7);
  testing_support::StemCase c = cases.front();
  c.geometry.distorted = true;
  const sim::RenderedStereoPair pair = sim::renderCylinderPair(c.geometry, c.scene);
  auto measurer = stem::StemMeasurer::create(pair.calibration, pair.left, pair.right);
  std::mt19937_64 rng(3);
  const stem::Points4 clicks = testing_support::jitteredClicks(c, 0.7, rng);
  stem::MeasureOptions options;
  options.refine_edges = refine;
  for (auto _ : state) {
    stem::StemMeasurement m = measurer->measure(clicks, options);
    benchmark::DoNotOptimize(m.diameter_mm);
    if (!m.ok())
      state.SkipWithError(m.message.c_str());
  }
}

BENCHMARK_CAPTURE(measureStem, d8mm_at_1_5m_refined, 8.0, 1.5, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(measureStem, d32mm_at_0_8m_refined, 32.0, 0.8, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(measureStem, d32mm_at_0_8m_face_value, 32.0, 0.8, false)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
