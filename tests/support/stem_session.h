// A recorded session of one FrameSet holding a rendered stereo pair as bottom_left/bottom_right
// (raw BayerRG8: a grey scene's mosaic is the grey image itself), with its calibration referenced
// in session.json as head_bottom: what the stem page serves in its tests.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <span>

#include "fieldrig/recording/session_writer.h"
#include "fieldrig/sim/cylinder_stereo_renderer.h"

namespace fieldrig::testing_support {

inline void writeStemSession(const std::filesystem::path& dir, const sim::RenderedStereoPair& pair,
                             const std::filesystem::path& calibration_dir) {
  recording::SessionInfo info;
  info.calibration.push_back({"head_bottom", calibration_dir.string()});
  recording::SessionWriter writer;
  ASSERT_TRUE(writer.open(dir, info).ok());
  recording::FrameSetRecord set;
  set.trigger_id = 1;
  set.location_id = "plot-0042";
  set.trigger_time = core::UtcTime{} + std::chrono::hours{24 * 20000};
  const cv::Mat* images[2] = {&pair.left, &pair.right};
  const char* names[2] = {"bottom_left", "bottom_right"};
  for (int camera = 0; camera < 2; ++camera) {
    recording::FrameView frame;
    frame.camera_index = camera;
    frame.camera_name = names[camera];
    frame.width = images[camera]->cols;
    frame.height = images[camera]->rows;
    frame.stride = images[camera]->cols;
    frame.pixel_format = core::PixelFormat::kBayerRG8;
    frame.pixels = std::span<const std::uint8_t>(images[camera]->data, images[camera]->total());
    frame.sequence = 1;
    set.frames.push_back(frame);
  }
  const recording::WriteOutcome outcome = writer.write(set);
  ASSERT_TRUE(outcome.ok()) << outcome.message;
  writer.close();
}

}  // namespace fieldrig::testing_support
