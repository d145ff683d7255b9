// libFuzzer target for gps::LocationMap::parse, the imaging-location map (CSV).
//
// Besides crashes and sanitizer reports: an error names the source and a line; a map that loads
// has every location in range with a unique, non-empty id and one value per metadata column; and
// what toCsv() writes of it loads again into the same map (`fieldrig map record` appends with
// csvLine(), so a location it cannot read back would be lost to the next run).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <set>
#include <string>
#include <string_view>

#include "fieldrig/gps/location_map.h"
#include "fuzz_support.h"

namespace {

using fieldrig::fuzz::check;
using fieldrig::fuzz::startsWith;
using fieldrig::gps::ImagingLocation;
using fieldrig::gps::LocationMap;

constexpr std::string_view kSource = "fuzz_map.csv";

void checkLoaded(const LocationMap& map) {
  std::set<std::string> ids;
  for (const ImagingLocation& location : map.locations()) {
    check(!location.id.empty(), "a location without an id");
    check(ids.insert(location.id).second, "a duplicate id was accepted");
    check(std::isfinite(location.latitude_deg) && std::fabs(location.latitude_deg) <= 90,
          "latitude out of range");
    check(std::isfinite(location.longitude_deg) && std::fabs(location.longitude_deg) <= 180,
          "longitude out of range");
    if (location.heading_deg) {
      check(std::isfinite(*location.heading_deg) && *location.heading_deg >= 0 &&
                *location.heading_deg < 360,
            "heading out of range");
    }
    check(location.metadata.size() == map.metadataColumns().size(),
          "metadata values and columns differ in number");
    check(map.find(location.id) == &location, "find() does not return the location of its id");
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  LocationMap map({"row", "plot", "note"});
  (void)map.add({"R01P01", 42.0106225, -93.7385, 0.0, {"1", "1", ""}});
  (void)map.add({"R01P02", -42.5, 179.999999, std::nullopt, {"1", "2", "a \"quoted\", note"}});
  (void)map.add({"edge", 90, -180, 359.999, {"", "", "line\nbreak"}});
  fieldrig::fuzz::writeSeed("written", map.toCsv());
  fieldrig::fuzz::writeSeed("comments", "# a field\nid,lat,lon\n# a comment\nA,1.5,2.5\n\n");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(bytes), size);
  const fieldrig::core::Result<LocationMap> parsed = LocationMap::parse(text, kSource);
  if (!parsed) {
    const std::string& message = parsed.error().message;
    check(startsWith(message, std::string(kSource) + ":"), "an error that does not name the file");
    return 0;
  }
  checkLoaded(*parsed);

  const std::string written = parsed->toCsv();
  const fieldrig::core::Result<LocationMap> again = LocationMap::parse(written, kSource);
  check(static_cast<bool>(again), "the map's own CSV does not load again");
  check(again->size() == parsed->size(), "the map's own CSV loads another number of locations");
  check(again->metadataColumns() == parsed->metadataColumns(), "metadata columns change");
  for (std::size_t i = 0; i < parsed->size(); ++i) {
    const ImagingLocation& a = parsed->locations()[i];
    const ImagingLocation& b = again->locations()[i];
    check(a.id == b.id && a.metadata == b.metadata, "an id or metadata value changes");
    check(a.latitude_deg == b.latitude_deg && a.longitude_deg == b.longitude_deg &&
              a.heading_deg == b.heading_deg,
          "a coordinate or heading changes when written and read again");
  }
  check(again->toCsv() == written, "writing the map again gives other text");
  return 0;
}
