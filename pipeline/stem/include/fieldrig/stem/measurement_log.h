// A session's stem measurements as a CSV file (one row per measurement, repeats numbered per
// stem) and the mean and SD of each stem's repeats (the paper measured every stem four times).
// The file survives a crash (core/durable_file.h): a save is one durable append, and removing the
// last measurement replaces the file atomically. One writer per file at a time: the functions do
// no locking of their own.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "fieldrig/core/result.h"
#include "fieldrig/stem/quadrangle.h"

namespace fieldrig::stem {

struct MeasurementRecord {
  std::string session;
  std::uint64_t set_index = 0;  // the FrameSet
  std::uint64_t trigger_id = 0;
  std::string head;  // bottom, middle, top
  std::string stem_label;
  Points4 points{};  // as clicked, raw left image
  double disparity_px = 0.0;
  double ncc = 0.0;
  double diameter_mm = 0.0;
  std::string time;  // ISO-8601 UTC of the measurement
  int repeat = 1;    // 1, 2, … per (session, stem label)
};

std::string csvHeader();
std::string toCsvRow(const MeasurementRecord& record);  // no newline

// Reads a file written with csvHeader/toCsvRow (RFC 4180: a quoted field may hold a line break,
// so a record may take several lines); a missing file is an empty log. The error names the file,
// the line where the record starts and the field.
core::Result<std::vector<MeasurementRecord>> readMeasurementLog(const std::filesystem::path& file);

// Appends one row (writing the header first when the file is new or empty) and waits until it
// is on the disk. The error names the file.
core::Result<void> appendMeasurement(const std::filesystem::path& file,
                                     const MeasurementRecord& record);

// Removes the last row of `session` (rows of other sessions sharing the file stay), rewriting the
// file atomically. nullopt when the session has no row; the error names the file.
core::Result<std::optional<MeasurementRecord>> removeLastMeasurement(
    const std::filesystem::path& file, const std::string& session);

// The repeat number the next measurement of `stem_label` in `session` gets.
int nextRepeat(const std::vector<MeasurementRecord>& records, const std::string& session,
               const std::string& stem_label);

struct StemSummary {
  std::string session;
  std::string stem_label;
  int count = 0;
  double mean_mm = 0.0;
  double sd_mm = 0.0;  // sample standard deviation (n − 1); 0 for one measurement
};

// One summary per (session, stem label), in order of first appearance.
std::vector<StemSummary> summarizeRepeats(const std::vector<MeasurementRecord>& records);

}  // namespace fieldrig::stem
