// Helpers shared by the recording tests: writing a few synthetic sets, reading files and lines.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "fieldrig/recording/session_reader.h"
#include "fieldrig/recording/session_writer.h"
#include "recording/synthetic_sets.h"
#include "support/cli_run.h"

namespace fieldrig::recording {

inline constexpr int kWidth = 40;
inline constexpr int kHeight = 30;

inline std::string locationFor(std::uint64_t trigger_id) {
  return "plot" + std::to_string(trigger_id % 3);
}

// Writes sets for triggers [first, first + count) and expects each write to succeed.
inline void writeSets(SessionWriter& writer, testing_support::SyntheticRig& rig,
                      std::uint64_t first, std::uint64_t count) {
  for (std::uint64_t trigger = first; trigger < first + count; ++trigger) {
    rig.fill(trigger);
    const WriteOutcome outcome = writer.write(rig.record(trigger, locationFor(trigger)));
    ASSERT_TRUE(outcome.ok()) << outcome.message;
  }
}

// Pixels of `trigger_id`'s frame of `camera` as the synthetic rig made them.
inline std::vector<std::uint8_t> expectedImage(std::uint64_t trigger_id, int camera, int width,
                                               int height) {
  std::vector<std::uint8_t> pixels;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x)
      pixels.push_back(testing_support::expectedPixel(trigger_id, camera, x, y));
  }
  return pixels;
}

inline void appendText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::app);
  out << text;
}

inline void writeText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

// Files in frames/ whose name ends with ".tmp".
inline int countTempFiles(const std::filesystem::path& session) {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(session / kFramesDir))
    count += entry.path().filename().string().ends_with(".tmp") ? 1 : 0;
  return count;
}

inline std::size_t countFiles(const std::filesystem::path& dir) {
  std::size_t count = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir))
    ++count;
  return count;
}

}  // namespace fieldrig::recording
