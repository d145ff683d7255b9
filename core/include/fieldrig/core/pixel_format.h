// Pixel formats of camera frames, shared by the drivers (which produce them) and the recording
// (which stores them). All are 8 bits per pixel; the Bayer names give the colour of the first two
// pixels of the first row (GenICam naming, as Aravis and the Grasshoppers' Format7 RAW8 use).
#pragma once

#include <optional>
#include <string_view>

namespace fieldrig::core {

enum class PixelFormat {
  kMono8,
  kBayerRG8,
  kBayerGR8,
  kBayerGB8,
  kBayerBG8,
};

inline std::string_view toString(PixelFormat format) {
  switch (format) {
    case PixelFormat::kMono8:
      return "Mono8";
    case PixelFormat::kBayerRG8:
      return "BayerRG8";
    case PixelFormat::kBayerGR8:
      return "BayerGR8";
    case PixelFormat::kBayerGB8:
      return "BayerGB8";
    case PixelFormat::kBayerBG8:
      return "BayerBG8";
  }
  return "unknown";
}

// The GenICam name back to the enum; nullopt for a name fieldrig does not handle.
inline std::optional<PixelFormat> parsePixelFormat(std::string_view name) {
  for (PixelFormat format : {PixelFormat::kMono8, PixelFormat::kBayerRG8, PixelFormat::kBayerGR8,
                             PixelFormat::kBayerGB8, PixelFormat::kBayerBG8}) {
    if (toString(format) == name)
      return format;
  }
  return std::nullopt;
}

}  // namespace fieldrig::core
