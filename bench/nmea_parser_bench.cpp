// Throughput of fieldrig::gps::NmeaParser::feed on an RTK receiver's 10 Hz RMC+GGA stream, next to
// a straightforward baseline (std::getline + split + std::stod) parsing the same bytes, so that the
// ratio can be read off one run: items_per_second is sentences per second.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "fieldrig/gps/nmea_parser.h"

namespace {

// Minutes with 8 decimals, as Trimble/CAT machine receivers send them.
std::string coordinate(double degrees, int degree_digits) {
  const double magnitude = std::fabs(degrees);
  const int whole = static_cast<int>(magnitude);
  char text[32];
  std::snprintf(text, sizeof text, "%0*d%011.8f", degree_digits, whole, (magnitude - whole) * 60.0);
  return text;
}

// A slow drive along a crop row: 10 Hz epochs, each an RMC and a GGA, RTK fixed.
std::string rtkStream(int epochs) {
  std::string out;
  double lat = 40.0821234567;
  double lon = -88.2193456789;
  for (int i = 0; i < epochs; ++i) {
    const int centis = i * 10;
    const int seconds = 13 * 3600 + 28 * 60 + centis / 100;
    char time[16];
    std::snprintf(time, sizeof time, "%02d%02d%02d.%02d", seconds / 3600, seconds / 60 % 60,
                  seconds % 60, centis % 100);
    lat += 1.8e-6;
    lon += 0.3e-6;
    const std::string lat_text = coordinate(lat, 2);
    const std::string lon_text = coordinate(lon, 3);
    char body[160];
    std::snprintf(body, sizeof body, "GNRMC,%s,A,%s,N,%s,W,3.889,9.5,140726,,,R", time,
                  lat_text.c_str(), lon_text.c_str());
    out += fieldrig::gps::withChecksum(body) + "\r\n";
    std::snprintf(body, sizeof body, "GNGGA,%s,%s,N,%s,W,4,17,0.7,%.3f,M,-33.4,M,1.0,0000", time,
                  lat_text.c_str(), lon_text.c_str(), 221.5 + 0.001 * (i % 50));
    out += fieldrig::gps::withChecksum(body) + "\r\n";
  }
  return out;
}

const std::string& stream() {
  static const std::string bytes = rtkStream(5000);
  return bytes;
}
constexpr int kSentences = 10000;

void BM_NmeaParserFeed(benchmark::State& state) {
  const std::string& bytes = stream();
  double sink = 0;
  fieldrig::gps::NmeaParser parser([&sink](const fieldrig::gps::Sentence& s) {
    if (s.kind == fieldrig::gps::SentenceKind::kRmc)
      sink += *s.rmc.latitude_deg;
    if (s.kind == fieldrig::gps::SentenceKind::kGga)
      sink += *s.gga.altitude_m;
  });
  const auto chunk = static_cast<std::size_t>(state.range(0));
  for (auto _ : state) {
    for (std::size_t pos = 0; pos < bytes.size(); pos += chunk) {
      parser.feed(std::string_view(bytes).substr(pos, chunk));
    }
    benchmark::DoNotOptimize(sink);
  }
  if (parser.stats().rmc + parser.stats().gga !=
      static_cast<std::uint64_t>(kSentences) * static_cast<std::uint64_t>(state.iterations())) {
    state.SkipWithError("the parser lost sentences");
  }
  state.SetItemsProcessed(state.iterations() * kSentences);
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(bytes.size()));
}
// 64 KiB is a file read; 64 bytes is roughly what a serial read returns at 115200 baud.
BENCHMARK(BM_NmeaParserFeed)->Arg(65536)->Arg(64);

// What one would write without care: a line stream, a vector of strings per sentence, stod.
// It checks the checksum and decodes the same fields, so the work is comparable.
void BM_BaselineGetlineSplitStod(benchmark::State& state) {
  const std::string& bytes = stream();
  double sink = 0;
  std::int64_t decoded = 0;
  for (auto _ : state) {
    std::istringstream in(bytes);
    std::string line;
    while (std::getline(in, line)) {
      if (!line.empty() && line.back() == '\r')
        line.pop_back();
      const std::size_t star = line.rfind('*');
      if (line.empty() || line[0] != '$' || star == std::string::npos)
        continue;
      unsigned sum = 0;
      for (std::size_t i = 1; i < star; ++i)
        sum ^= static_cast<unsigned char>(line[i]);
      if (sum != std::stoul(line.substr(star + 1), nullptr, 16))
        continue;
      std::vector<std::string> fields;
      std::stringstream body(line.substr(1, star - 1));
      std::string field;
      while (std::getline(body, field, ','))
        fields.push_back(field);
      auto degrees = [](const std::string& text, const std::string& hemisphere) {
        const double value = std::stod(text);
        const double whole = std::floor(value / 100.0);
        const double result = whole + (value - whole * 100.0) / 60.0;
        return hemisphere == "S" || hemisphere == "W" ? -result : result;
      };
      const std::string type = fields[0].substr(2);
      if (type == "RMC") {
        sink += std::stod(fields[1]) + degrees(fields[3], fields[4]) +
                degrees(fields[5], fields[6]) + std::stod(fields[7]) * 1852.0 / 3600.0 +
                std::stod(fields[8]) + std::stoi(fields[9]);
        ++decoded;
      } else if (type == "GGA") {
        sink += std::stod(fields[1]) + degrees(fields[2], fields[3]) +
                degrees(fields[4], fields[5]) + std::stoi(fields[6]) + std::stoi(fields[7]) +
                std::stod(fields[8]) + std::stod(fields[9]) + std::stod(fields[11]);
        ++decoded;
      }
    }
    benchmark::DoNotOptimize(sink);
  }
  if (decoded != kSentences * state.iterations())
    state.SkipWithError("baseline lost sentences");
  state.SetItemsProcessed(state.iterations() * kSentences);
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(bytes.size()));
}
BENCHMARK(BM_BaselineGetlineSplitStod);

}  // namespace

BENCHMARK_MAIN();
