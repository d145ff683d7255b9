// Helpers shared by `fieldrig stem` and `fieldrig stem-ui`: parsing points, loading images
// (grey or raw Bayer) and a measurement as JSON.
#pragma once

#include <CLI/CLI.hpp>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>

#include "fieldrig/core/pixel_format.h"
#include "fieldrig/core/result.h"
#include "fieldrig/stem/stem_measurer.h"

namespace fieldrig::tools {

// "x1,y1,…,x4,y4": eight finite numbers.
core::Result<stem::Points4> parseStemPoints(const std::string& text);

// An image file as 8-bit grey; `bayer` ("", "RG", "GR", "GB", "BG") demosaics raw Bayer.
core::Result<cv::Mat> loadGreyImage(const std::filesystem::path& file, const std::string& bayer);

// Raw 8-bit pixels of a recorded frame in `format` → grey.
cv::Mat toGrey(const cv::Mat& raw, core::PixelFormat format);

nlohmann::ordered_json measurementJson(const stem::StemMeasurement& m);

// `fieldrig stem-ui`, in stem_ui_server.cpp.
void registerStemUiCommand(CLI::App& app, int& exit_code);

}  // namespace fieldrig::tools
