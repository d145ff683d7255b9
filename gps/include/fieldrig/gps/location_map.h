// Imaging-location maps: where the cameras must fire, recorded once per field and season.
//
// The file is CSV: a header naming at least `id,lat,lon`, optionally `heading` (degrees true,
// the direction of travel when the image must be taken); any further columns (plot, range,
// row…) are kept as metadata, in order. Lines starting with '#' are comments. Errors name the
// file, line and field; duplicate ids and non-numbers are errors.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "fieldrig/core/result.h"

namespace fieldrig::gps {

struct ImagingLocation {
  std::string id;
  double latitude_deg = 0;
  double longitude_deg = 0;
  std::optional<double> heading_deg;  // direction of travel required, degrees true
  std::vector<std::string> metadata;  // one value per LocationMap::metadataColumns()
};

class LocationMap {
 public:
  LocationMap() = default;
  explicit LocationMap(std::vector<std::string> metadata_columns);

  // Reads a map file; the error names the file, line and field.
  static core::Result<LocationMap> load(const std::filesystem::path& path);
  // Parses map text; `source_name` stands for the file name in errors.
  static core::Result<LocationMap> parse(std::string_view text, std::string_view source_name);

  // Writes the map (header, then one line per location); returns an error naming the file.
  core::Result<void> save(const std::filesystem::path& path) const;
  std::string toCsv() const;
  // One CSV line (with newline) for `location`, as toCsv() writes it; for append-as-you-go writers.
  std::string csvLine(const ImagingLocation& location) const;
  std::string csvHeader() const;

  // Adds a location; an error if its id is already used or its numbers are out of range.
  core::Result<void> add(ImagingLocation location);

  const std::vector<ImagingLocation>& locations() const { return locations_; }
  const std::vector<std::string>& metadataColumns() const { return metadata_columns_; }
  std::size_t size() const { return locations_.size(); }
  bool empty() const { return locations_.empty(); }
  const ImagingLocation* find(std::string_view id) const;

 private:
  std::vector<std::string> metadata_columns_;
  std::vector<ImagingLocation> locations_;
  std::unordered_map<std::string, std::size_t> index_by_id_;
};

}  // namespace fieldrig::gps
