// One plot from its set of per-head images: the three heads matched and fused into one cloud in
// the plot frame (cloud::CloudBuilder), then the plot's traits (traits::computeTraits). The one
// processor behind the daemon's live processing and `fieldrig process`; only the adapters that
// make head images (from a live FrameSet, from a recorded set) differ.
//
// Thread contract: thread-compatible; one instance per processing thread (the matchers keep
// buffers). Never throws for bad images: a head that cannot be used is left out and named.
#pragma once

#include <string>
#include <vector>

#include "fieldrig/cloud/fusion.h"
#include "fieldrig/core/result.h"
#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::pipeline {

struct ProcessorOptions {
  cloud::CloudOptions cloud;
  traits::TraitsOptions traits;
  bool keep_cloud = false;  // hand back the fused cloud (for `--clouds`); it costs a copy
};

struct PlotResult {
  traits::TraitsResult traits;
  std::size_t cloud_points = 0;
  bool partial = false;                  // some head was left out of the cloud
  std::vector<std::string> problems;     // the adapter's and the heads' problems, in that order
  std::vector<cloud::HeadStatus> heads;  // per head: used or why not, points, coverage
  cloud::DepthSource depth_source = cloud::DepthSource::kStereo;
  cloud::Cloud cloud;   // only with keep_cloud
  double cloud_ms = 0;  // stereo and fusion
  double traits_ms = 0;
};

class PlotProcessor {
 public:
  // Builds each head's rectification maps and matcher once.
  static core::Result<PlotProcessor> create(const cloud::RigCalibration& rig,
                                            ProcessorOptions options = {});

  // `heads` in the order of rig().heads (an empty image marks a missing camera); `problems` are
  // what the adapter found on the way (they lead the result's list).
  PlotResult process(const std::vector<cloud::HeadFrames>& heads,
                     std::vector<std::string> problems = {});

  const cloud::RigCalibration& rig() const { return builder_.rig(); }
  const ProcessorOptions& options() const { return options_; }

 private:
  PlotProcessor(cloud::CloudBuilder builder, ProcessorOptions options)
      : builder_(std::move(builder)), options_(std::move(options)) {}

  cloud::CloudBuilder builder_;
  ProcessorOptions options_;
};

}  // namespace fieldrig::pipeline
