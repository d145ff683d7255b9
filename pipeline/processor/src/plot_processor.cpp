#include "fieldrig/pipeline/plot_processor.h"

#include "fieldrig/core/time.h"

namespace fieldrig::pipeline {

core::Result<PlotProcessor> PlotProcessor::create(const cloud::RigCalibration& rig,
                                                  ProcessorOptions options) {
  auto builder = cloud::CloudBuilder::create(rig, options.cloud);
  if (!builder)
    return builder.error();
  return PlotProcessor(std::move(*builder), std::move(options));
}

PlotResult PlotProcessor::process(const std::vector<cloud::HeadFrames>& heads,
                                  std::vector<std::string> problems) {
  PlotResult result;
  result.problems = std::move(problems);
  result.depth_source = options_.cloud.depth_source;
  const auto cloud_start = std::chrono::steady_clock::now();
  cloud::FusionResult fused = builder_.build(heads);
  result.cloud_ms = core::millisecondsSince(cloud_start);
  result.partial = fused.partial();
  for (const cloud::HeadStatus& head : fused.heads) {
    if (!head.ok)
      result.problems.push_back("head " + head.name + " left out: " + head.problem);
    else if (!head.truth_problem.empty())
      result.problems.push_back("head " + head.name +
                                " not scored against the truth: " + head.truth_problem);
  }
  result.heads = fused.heads;
  result.cloud_points = fused.cloud.size();
  std::vector<Eigen::Vector3f> points;
  points.reserve(fused.cloud.size());
  for (const auto& point : fused.cloud)
    points.emplace_back(point.x, point.y, point.z);
  const auto traits_start = std::chrono::steady_clock::now();
  result.traits = traits::computeTraits(points, traits::InputFrame::kPlot, options_.traits);
  result.traits_ms = core::millisecondsSince(traits_start);
  if (options_.keep_cloud)
    result.cloud = std::move(fused.cloud);
  return result;
}

}  // namespace fieldrig::pipeline
