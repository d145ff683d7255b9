// The rig's layout: its stereo heads from the bottom up, each a left and a right camera. The one
// place that says how cameras are named ("bottom_left") and ordered (bottom L/R, middle L/R,
// top L/R): the config, the rig, the recorder, the plot processor and the simulators use it.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fieldrig::core {

enum class CameraSide { kLeft = 0, kRight = 1 };

struct RigLayout {
  // Head names from the bottom up; a head's cameras are NAME_left and NAME_right.
  std::vector<std::string> heads{"bottom", "middle", "top"};

  std::size_t cameraCount() const { return heads.size() * 2; }

  static std::string cameraName(std::string_view head, CameraSide side) {
    return std::string(head) + (side == CameraSide::kLeft ? "_left" : "_right");
  }
  // Camera `index` in rig order (2·head + side).
  std::string cameraName(std::size_t index) const {
    return cameraName(heads.at(index / 2), index % 2 ? CameraSide::kRight : CameraSide::kLeft);
  }
  std::size_t cameraIndex(std::size_t head, CameraSide side) const {
    return 2 * head + static_cast<std::size_t>(side);
  }
  std::vector<std::string> cameraNames() const {
    std::vector<std::string> names;
    for (std::size_t i = 0; i < cameraCount(); ++i)
      names.push_back(cameraName(i));
    return names;
  }
  // The rig index of a camera name, nullopt when no head of this layout has it.
  std::optional<std::size_t> findCamera(std::string_view name) const {
    for (std::size_t i = 0; i < cameraCount(); ++i) {
      if (cameraName(i) == name)
        return i;
    }
    return std::nullopt;
  }
};

}  // namespace fieldrig::core
