#include "fieldrig/config/config.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string_view>
#include <system_error>
#include <utility>

#include "fieldrig/core/frame.h"
#include "fieldrig/core/pixel_format.h"

namespace fieldrig::config {
namespace {

namespace fs = std::filesystem;

// The loader's one failure, already worded "FILE:LINE: key.path: what". Thrown inside this file
// only and turned into a core::Error at the entry points (start-up code, never the live path).
struct LoadFailure {
  std::string message;
};

// Where the text came from: it names the text in messages and anchors its relative paths.
struct Source {
  std::string origin;
  fs::path base_dir;
};

std::string lineSuffix(const YAML::Mark& mark) {
  if (mark.is_null() || mark.line < 0)
    return {};
  return ":" + std::to_string(mark.line + 1);
}

std::string formatNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// "a, b or c" (choices), or "a, b, c" with last_separator ", " (a sequence).
std::string joinNames(const std::vector<std::string>& names,
                      const std::string& last_separator = " or ") {
  std::string joined;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0)
      joined += i + 1 == names.size() ? last_separator : ", ";
    joined += names[i];
  }
  return joined;
}

// Edit distance, for "did you mean" on unknown keys.
std::size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j)
    row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// One value of the file: its node, its key path ("gps.serial.baud") and the place errors point
// at. Readers fail with a LoadFailure naming all three.
class Value {
 public:
  Value(const Source& source, YAML::Node node, std::string key_path, YAML::Mark mark)
      : source_(&source), node_(std::move(node)), key_path_(std::move(key_path)), mark_(mark) {}

  const Source& source() const { return *source_; }
  const YAML::Node& node() const { return node_; }
  const std::string& keyPath() const { return key_path_; }
  const YAML::Mark& mark() const { return mark_; }
  int line() const { return mark_.line + 1; }
  std::string childPath(std::string_view key) const {
    return key_path_.empty() ? std::string(key) : key_path_ + "." + std::string(key);
  }

  [[noreturn]] void fail(const std::string& what) const {
    std::string message = source_->origin + lineSuffix(mark_) + ": ";
    if (!key_path_.empty())
      message += key_path_ + ": ";
    throw LoadFailure{message + what};
  }

  // What the node is, for "expected …, got …".
  std::string describe() const {
    if (node_.IsNull())
      return "nothing";
    if (node_.IsSequence())
      return "a list";
    if (node_.IsMap())
      return "a map";
    if (isPlainScalar())
      return "'" + node_.Scalar() + "'";
    return "the string \"" + node_.Scalar() + "\"";
  }

  // Any scalar, quoted or not.
  const std::string& text() const {
    if (!node_.IsScalar())
      fail("expected a text value, got " + describe());
    return node_.Scalar();
  }

  double number() const {
    const std::string& t = plainScalar("a number");
    std::string_view digits = t;
    if (digits.starts_with('+'))
      digits.remove_prefix(1);
    double value = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec != std::errc() || end != digits.data() + digits.size() || digits.empty())
      fail("expected a number, got " + describe());
    if (!std::isfinite(value))
      fail(t + " is not a finite number");
    return value;
  }

  std::int64_t integer() const {
    const std::string& t = plainScalar("an integer");
    std::string_view digits = t;
    if (digits.starts_with('+'))
      digits.remove_prefix(1);
    std::int64_t value = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec == std::errc::result_out_of_range)
      fail(t + " is out of range");
    if (ec != std::errc() || end != digits.data() + digits.size() || digits.empty())
      fail("expected an integer, got " + describe());
    return value;
  }

  bool boolean() const {
    std::string t = plainScalar("true or false");
    std::transform(t.begin(), t.end(), t.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (t == "true" || t == "yes" || t == "on")
      return true;
    if (t == "false" || t == "no" || t == "off")
      return false;
    fail("expected true or false, got " + describe());
  }

  // A file or folder; a relative one is taken relative to the configuration file's folder.
  // Empty stays empty (nothing configured).
  fs::path path() const {
    const std::string& t = text();
    if (t.empty())
      return {};
    fs::path p(t);
    if (p.is_relative() && !source_->base_dir.empty())
      p = source_->base_dir / p;
    return p.lexically_normal();
  }

  // The elements of a list, each with its path "key[i]".
  std::vector<Value> list() const {
    if (!node_.IsSequence())
      fail("expected a list, got " + describe());
    std::vector<Value> items;
    for (std::size_t i = 0; i < node_.size(); ++i) {
      const YAML::Node item = node_[i];
      items.emplace_back(*source_, item, key_path_ + "[" + std::to_string(i) + "]",
                         item.Mark().is_null() ? mark_ : item.Mark());
    }
    return items;
  }

 private:
  bool isPlainScalar() const { return node_.IsScalar() && node_.Tag() == "?"; }

  // Numbers and booleans are plain scalars: a quoted "115200" is a string, and an error.
  const std::string& plainScalar(const std::string& expected) const {
    if (!isPlainScalar())
      fail("expected " + expected + ", got " + describe());
    return node_.Scalar();
  }

  const Source* source_;
  YAML::Node node_;
  std::string key_path_;
  YAML::Mark mark_;
};

// --- Range-checked readers ----------------------------------------------------------------------

// Every number of the file is finite (Value::number) and bounded above too: a value beyond `hi`
// is a typo or a unit mistake that would otherwise make the daemon wait, allocate or miss for
// ever. The defaults of `hi` are for the few values with no natural ceiling.
double readPositive(const Value& v, double hi = std::numeric_limits<double>::max()) {
  const double x = v.number();
  if (!(x > 0))
    v.fail(v.node().Scalar() + " must be positive");
  if (x > hi)
    v.fail(v.node().Scalar() + " is out of range (0, " + formatNumber(hi) + "]");
  return x;
}

double readNonNegative(const Value& v, double hi = std::numeric_limits<double>::max()) {
  const double x = v.number();
  if (x < 0)
    v.fail(v.node().Scalar() + " must not be negative");
  if (x > hi)
    v.fail(v.node().Scalar() + " is out of range [0, " + formatNumber(hi) + "]");
  return x;
}

// [lo, hi], or [lo, hi) when hi_open.
double readNumberIn(const Value& v, double lo, double hi, bool hi_open = false) {
  const double x = v.number();
  if (x < lo || x > hi || (hi_open && x == hi)) {
    v.fail(v.node().Scalar() + " is out of range [" + formatNumber(lo) + ", " + formatNumber(hi) +
           (hi_open ? ")" : "]"));
  }
  return x;
}

std::int64_t readIntegerIn(const Value& v, std::int64_t lo, std::int64_t hi) {
  const std::int64_t x = v.integer();
  if (x >= lo && x <= hi)
    return x;
  const bool no_upper_limit =
      hi == std::numeric_limits<std::int64_t>::max() || hi == std::numeric_limits<int>::max();
  const bool no_lower_limit =
      lo == std::numeric_limits<std::int64_t>::min() || lo == std::numeric_limits<int>::min();
  if (no_upper_limit && x > hi)
    v.fail(v.node().Scalar() + " is too large");
  if (no_upper_limit && !no_lower_limit) {
    if (lo == 0)
      v.fail(v.node().Scalar() + " must not be negative");
    if (lo == 1)
      v.fail(v.node().Scalar() + " must be positive");
    v.fail(v.node().Scalar() + " must be at least " + std::to_string(lo));
  }
  v.fail(v.node().Scalar() + " is out of range (" + std::to_string(lo) + " … " +
         std::to_string(hi) + ")");
}

int readInt(const Value& v, int lo = std::numeric_limits<int>::min(),
            int hi = std::numeric_limits<int>::max()) {
  return static_cast<int>(readIntegerIn(v, lo, hi));
}

std::string readNonEmptyText(const Value& v) {
  const std::string& t = v.text();
  if (t.empty())
    v.fail("must not be empty");
  return t;
}

template <typename E>
using Names = std::vector<std::pair<std::string_view, E>>;

template <typename E>
E readChoice(const Value& v, const Names<E>& names) {
  const std::string& t = v.text();
  std::vector<std::string> known;
  for (const auto& [name, value] : names) {
    if (name == t)
      return value;
    known.emplace_back(name);
  }
  v.fail("'" + t + "' is not one of " + joinNames(known));
}

// --- Maps of keys
// ---------------------------------------------------------------------------------

using Handler = std::function<void(const Value&)>;
using Handlers = std::vector<std::pair<std::string_view, Handler>>;
// The keys a map held, for checks between keys.
using Entries = std::map<std::string, Value, std::less<>>;

// Hands each key of the map (in file order) to its handler; an unknown or repeated key is an
// error. Nothing (a section whose keys are all commented out) reads as an empty map.
Entries readMap(const Value& section, const Handlers& handlers) {
  Entries entries;
  const YAML::Node& node = section.node();
  if (node.IsNull())
    return entries;
  if (!node.IsMap())
    section.fail("expected a map of keys, got " + section.describe());
  for (auto it = node.begin(); it != node.end(); ++it) {
    const YAML::Node key_node = it->first;
    const YAML::Node value_node = it->second;
    const Value key(section.source(), key_node, section.keyPath(), key_node.Mark());
    if (!key_node.IsScalar())
      key.fail("expected a key name, got " + key.describe());
    const std::string& name = key_node.Scalar();
    const Value at_key(section.source(), key_node, section.childPath(name), key_node.Mark());
    const auto handler = std::find_if(handlers.begin(), handlers.end(),
                                      [&](const auto& entry) { return entry.first == name; });
    if (handler == handlers.end()) {
      std::vector<std::string> known;
      std::string_view nearest;
      std::size_t nearest_distance = 3;
      for (const auto& [known_name, _] : handlers) {
        known.emplace_back(known_name);
        const std::size_t distance = editDistance(name, known_name);
        if (distance < nearest_distance) {
          nearest = known_name;
          nearest_distance = distance;
        }
      }
      if (!nearest.empty())
        at_key.fail("unknown key (did you mean '" + std::string(nearest) + "'?)");
      at_key.fail("unknown key (known here: " + joinNames(known) + ")");
    }
    if (const auto first = entries.find(name); first != entries.end())
      at_key.fail("given twice (first on line " + std::to_string(first->second.line()) + ")");
    // A key without a value has no useful place of its own: point at the key.
    const YAML::Mark mark =
        value_node.IsNull() || value_node.Mark().is_null() ? key_node.Mark() : value_node.Mark();
    const Value value(section.source(), value_node, section.childPath(name), mark);
    entries.emplace(name, value);
    handler->second(value);
  }
  return entries;
}

// Handlers that store into a field.
Handler positive(double& field, double hi = std::numeric_limits<double>::max()) {
  return [&field, hi](const Value& v) { field = readPositive(v, hi); };
}
Handler nonNegative(double& field, double hi = std::numeric_limits<double>::max()) {
  return [&field, hi](const Value& v) { field = readNonNegative(v, hi); };
}
Handler numberIn(double& field, double lo, double hi, bool hi_open = false) {
  return [&field, lo, hi, hi_open](const Value& v) { field = readNumberIn(v, lo, hi, hi_open); };
}
Handler integer(int& field, int lo = std::numeric_limits<int>::min(),
                int hi = std::numeric_limits<int>::max()) {
  return [&field, lo, hi](const Value& v) { field = readInt(v, lo, hi); };
}
Handler flag(bool& field) {
  return [&field](const Value& v) { field = v.boolean(); };
}
Handler location(fs::path& field) {
  return [&field](const Value& v) { field = v.path(); };
}
template <typename E>
Handler choice(E& field, Names<E> names) {
  return [&field, names = std::move(names)](const Value& v) { field = readChoice(v, names); };
}

// The entry of `key` if the map held it, else the section (for the place of an error).
const Value& entryOr(const Entries& entries, std::string_view key, const Value& section) {
  const auto it = entries.find(key);
  return it == entries.end() ? section : it->second;
}

// --- Sections ---------------------------------------------------------------------------------

constexpr unsigned kStandardBaudRates[] = {4800, 9600, 19200, 38400, 57600, 115200};

// Ceilings shared by several keys: an hour between serial retries, a minute for anything the
// trigger chain or a camera waits for, a second of lead or latency (a plot is passed in ~2 s).
constexpr std::int64_t kMaxRetryMs = 3'600'000;
constexpr std::int64_t kMaxFrameTimeoutMs = 60'000;
constexpr double kMaxWaitS = 60;
constexpr double kMaxLeadS = 1;
// As `fieldrig acquire`: the largest machine-vision sensors are ~14k pixels wide, and the frame
// pool's own budget check refuses what does not fit in memory.
constexpr int kMaxFrameSide = 16384;
constexpr std::int64_t kMaxPoolSets = 1024;

void readSerial(const Value& section, gps::SerialOptions& serial) {
  const Entries entries = readMap(
      section,
      {
          {"device", [&](const Value& v) { serial.device = v.text(); }},
          {"baud",
           [&](const Value& v) {
             const std::int64_t baud = v.integer();
             const bool standard = std::any_of(
                 std::begin(kStandardBaudRates), std::end(kStandardBaudRates),
                 [baud](unsigned rate) { return static_cast<std::int64_t>(rate) == baud; });
             if (!standard) {
               v.fail(v.node().Scalar() +
                      " is not a standard baud rate (4800, 9600, 19200, 38400, 57600 or 115200)");
             }
             serial.baud = static_cast<unsigned>(baud);
           }},
          {"reopen_initial_ms",
           [&](const Value& v) {
             serial.reopen_initial_delay =
                 std::chrono::milliseconds{readIntegerIn(v, 1, kMaxRetryMs)};
           }},
          {"reopen_max_ms",
           [&](const Value& v) {
             serial.reopen_max_delay = std::chrono::milliseconds{readIntegerIn(v, 1, kMaxRetryMs)};
           }},
      });
  if (serial.reopen_max_delay < serial.reopen_initial_delay) {
    const Value& at = entries.contains("reopen_max_ms")
                          ? entries.at("reopen_max_ms")
                          : entryOr(entries, "reopen_initial_ms", section);
    at.fail("the reopen delays must satisfy reopen_initial_ms (" +
            std::to_string(serial.reopen_initial_delay.count()) + ") <= reopen_max_ms (" +
            std::to_string(serial.reopen_max_delay.count()) + ")");
  }
}

void readPlanner(const Value& section, gps::TriggerOptions& o) {
  readMap(section,
          {
              {"cross_track_tolerance_m", positive(o.cross_track_tolerance_m, 100)},
              {"heading_tolerance_deg", numberIn(o.heading_tolerance_deg, 0, 180)},
              {"min_speed_mps", nonNegative(o.min_speed_mps, 50)},
              {"max_fix_age_s", positive(o.max_fix_age_s, kMaxWaitS)},
              {"max_fix_gap_s", positive(o.max_fix_gap_s, kMaxWaitS)},
              {"min_trigger_interval_s", nonNegative(o.min_trigger_interval_s, kMaxWaitS)},
              {"late_tolerance_m", nonNegative(o.late_tolerance_m, 100)},
              {"rearm_distance_m", nonNegative(o.rearm_distance_m, 1000)},
              {"fit_window_s", positive(o.fit_window_s, kMaxWaitS)},
              {"fit_residual_limit_m", positive(o.fit_residual_limit_m, 100)},
              {"trigger_lead_s", nonNegative(o.trigger_lead_s, kMaxLeadS)},
              {"motion_model",
               choice(o.motion_model,
                      Names<gps::MotionModel>{
                          {"kalman", gps::MotionModel::kKalman},
                          {"constant_velocity_fit", gps::MotionModel::kConstantVelocityFit},
                      })},
              {"kalman_jerk_density", positive(o.kalman_jerk_density, 1000)},
              {"kalman_position_sd_m", positive(o.kalman_position_sd_m, 100)},
              {"kalman_velocity_sd_mps", positive(o.kalman_velocity_sd_mps, 100)},
          });
}

void readGps(const Value& section, GpsConfig& gps) {
  readMap(section, {
                       {"serial", [&](const Value& v) { readSerial(v, gps.serial); }},
                       {"latency_s", nonNegative(gps.triggers.latency_s, kMaxLeadS)},
                       {"planner", [&](const Value& v) { readPlanner(v, gps.triggers.planner); }},
                   });
}

// Head names become camera names ("bottom_left") and calibration folder names.
std::vector<std::string> readHeads(const Value& v) {
  const std::vector<Value> items = v.list();
  constexpr std::size_t kMaxHeads = core::FrameSet::kMaxCameras / 2;
  if (items.empty() || items.size() > kMaxHeads) {
    v.fail(std::to_string(items.size()) + " heads; a rig has 1 to " + std::to_string(kMaxHeads));
  }
  std::vector<std::string> heads;
  for (const Value& item : items) {
    const std::string name = readNonEmptyText(item);
    const bool usable = std::all_of(name.begin(), name.end(), [](unsigned char c) {
      return std::isalnum(c) || c == '_' || c == '-';
    });
    if (!usable) {
      item.fail("'" + name +
                "' is not a usable head name (letters, digits, '_' and '-'; it names folders)");
    }
    if (std::find(heads.begin(), heads.end(), name) != heads.end())
      item.fail("head '" + name + "' is named twice");
    heads.push_back(name);
  }
  return heads;
}

std::map<std::string, std::string> readCameraOptions(const Value& section) {
  std::map<std::string, std::string> options;
  const YAML::Node& node = section.node();
  if (node.IsNull())
    return options;
  if (!node.IsMap())
    section.fail("expected a map of driver options, got " + section.describe());
  for (auto it = node.begin(); it != node.end(); ++it) {
    const Value key(section.source(), it->first, section.keyPath(), it->first.Mark());
    const std::string name = readNonEmptyText(key);
    const YAML::Node value_node = it->second;
    const Value value(section.source(), value_node, section.childPath(name),
                      value_node.IsNull() ? it->first.Mark() : value_node.Mark());
    if (options.contains(name))
      value.fail("given twice");
    if (!value_node.IsScalar())
      value.fail("expected a single value, got " + value.describe());
    options[name] = value_node.Scalar();
  }
  return options;
}

void readCameras(const Value& section, CamerasConfig& cameras) {
  drivers::RigOptions& rig = cameras.rig;
  drivers::CameraConfig shared;  // what every camera is configured with, but its id
  std::optional<Value> ids_value;
  std::vector<std::string> ids;
  readMap(section,
          {
              {"driver", [&](const Value& v) { rig.driver = readNonEmptyText(v); }},
              {"heads", [&](const Value& v) { cameras.layout.heads = readHeads(v); }},
              {"ids",
               [&](const Value& v) {
                 ids_value = v;
                 for (const Value& item : v.list()) {
                   const std::string id = readNonEmptyText(item);
                   if (std::find(ids.begin(), ids.end(), id) != ids.end())
                     item.fail("camera id '" + id + "' is given twice");
                   ids.push_back(id);
                 }
               }},
              {"width",
               [&](const Value& v) {
                 shared.width = static_cast<std::uint32_t>(readInt(v, 1, kMaxFrameSide));
               }},
              {"height",
               [&](const Value& v) {
                 shared.height = static_cast<std::uint32_t>(readInt(v, 1, kMaxFrameSide));
               }},
              {"pixel_format",
               [&](const Value& v) {
                 const std::string& name = v.text();
                 const auto format = core::parsePixelFormat(name);
                 if (!format) {
                   v.fail("'" + name +
                          "' is not one of Mono8, BayerRG8, BayerGR8, BayerGB8 or BayerBG8");
                 }
                 shared.format = *format;
               }},
              {"exposure_us", positive(shared.exposure_us, 10'000'000)},
              {"gain_db", numberIn(shared.gain_db, -100, 100)},
              {"white_balance",
               [&](const Value& v) {
                 const std::vector<Value> gains = v.list();
                 if (gains.size() != 2)
                   v.fail("expected two gains [blue, red], got " + std::to_string(gains.size()));
                 shared.white_balance =
                     std::make_pair(readPositive(gains[0], 100), readPositive(gains[1], 100));
               }},
              {"trigger", choice(shared.trigger,
                                 Names<drivers::TriggerSource>{
                                     {"software", drivers::TriggerSource::kSoftware},
                                     {"external", drivers::TriggerSource::kExternal},
                                 })},
              {"frame_timeout_ms",
               [&](const Value& v) {
                 rig.frame_timeout =
                     std::chrono::milliseconds{readIntegerIn(v, 1, kMaxFrameTimeoutMs)};
               }},
              {"max_skew_us",
               [&](const Value& v) {
                 rig.max_skew = std::chrono::microseconds{readIntegerIn(v, 0, 1'000'000)};
               }},
              {"pool_sets",
               [&](const Value& v) {
                 rig.pool_sets = static_cast<std::size_t>(readIntegerIn(v, 1, kMaxPoolSets));
               }},
              {"options", [&](const Value& v) { shared.options = readCameraOptions(v); }},
          });

  const std::size_t count = cameras.layout.cameraCount();
  if (ids_value) {
    if (ids.size() != count) {
      ids_value->fail(std::to_string(ids.size()) + " ids for " + std::to_string(count) +
                      " cameras: one id per camera, in rig order (" +
                      joinNames(cameras.layout.cameraNames(), ", ") + ")");
    }
  } else {
    // The sim driver's ids are camera indices; a hardware driver without ids gets empty ones,
    // which it refuses naming the camera.
    for (std::size_t i = 0; i < count; ++i)
      ids.push_back(rig.driver == "sim" ? std::to_string(i) : std::string());
  }
  rig.cameras.clear();
  for (std::size_t i = 0; i < count; ++i) {
    drivers::CameraConfig camera = shared;
    camera.id = ids[i];
    rig.cameras.push_back(std::move(camera));
  }
}

void readRecording(const Value& section, RecordingConfig& recording) {
  readMap(section, {
                       {"dir", location(recording.dir)},
                       {"fsync",
                        [&](const Value& v) {
                          const std::string& name = v.text();
                          const auto policy = recording::parseFsyncPolicy(name);
                          if (!policy)
                            v.fail("'" + name + "' is not one of none, per_set or per_frame");
                          recording.writer.fsync = *policy;
                        }},
                   });
}

void readMatcher(const Value& section, stereo::MatcherOptions& o) {
  readMap(section,
          {
              {"num_disparities",
               [&](const Value& v) {
                 const int n = readInt(v);
                 if (n <= 0 || n % 16 != 0)
                   v.fail(v.node().Scalar() + " is not a positive multiple of 16");
                 o.num_disparities = n;
               }},
              {"min_disparity", integer(o.min_disparity)},
              {"block_size",
               [&](const Value& v) {
                 const int size = readInt(v, 1);
                 if (size % 2 == 0)
                   v.fail(v.node().Scalar() + " is even; the block size must be odd");
                 o.block_size = size;
               }},
              {"p1_per_pixel", integer(o.p1_per_pixel, 0)},
              {"p2_per_pixel", integer(o.p2_per_pixel, 0)},
              {"pre_filter_cap", integer(o.pre_filter_cap, 0)},
              {"uniqueness_ratio", integer(o.uniqueness_ratio, 0, 100)},
              {"speckle_window", integer(o.speckle_window, 0)},
              {"speckle_range", integer(o.speckle_range, 0)},
              {"disp12_max_diff", integer(o.disp12_max_diff, -1)},
              {"lr_check", flag(o.lr_check)},
              {"lr_max_diff",
               [&](const Value& v) { o.lr_max_diff = static_cast<float>(readNonNegative(v)); }},
              {"wls", flag(o.wls)},
              {"wls_lambda", nonNegative(o.wls_lambda)},
              {"wls_sigma", positive(o.wls_sigma)},
              {"mode", choice(o.mode,
                              Names<int>{
                                  {"sgbm", cv::StereoSGBM::MODE_SGBM},
                                  {"hh", cv::StereoSGBM::MODE_HH},
                                  {"sgbm_3way", cv::StereoSGBM::MODE_SGBM_3WAY},
                                  {"hh4", cv::StereoSGBM::MODE_HH4},
                              })},
              {"match_colour", flag(o.match_colour)},
              {"full_width", flag(o.full_width)},
              {"min_texture", numberIn(o.min_texture, 0, stereo::kMaxMinTexture)},
          });
  // The library's own ranges (and those across keys), so the file and the command line agree.
  if (auto valid = stereo::validate(o); !valid)
    section.fail(valid.error().message);
}

// The traits keys: the field names, as the JSON loader of earlier versions read them, so that
// their traits files still load.
void readTraits(const Value& section, traits::TraitsOptions& o) {
  const Entries entries = readMap(
      section,
      {
          {"camera_to_plot",
           [&](const Value& v) {
             const std::vector<Value> rows = v.list();
             if (rows.size() != 3)
               v.fail("expected 3 rows of 3 numbers, got " + std::to_string(rows.size()) + " rows");
             for (int r = 0; r < 3; ++r) {
               const Value& row = rows[static_cast<std::size_t>(r)];
               const std::vector<Value> cells = row.list();
               if (cells.size() != 3)
                 row.fail("expected 3 numbers, got " + std::to_string(cells.size()));
               for (int c = 0; c < 3; ++c)
                 o.camera_to_plot(r, c) = cells[static_cast<std::size_t>(c)].number();
             }
           }},
          {"voxel_leaf_m", positive(o.voxel_leaf_m)},
          {"outlier_method",
           choice(o.outlier_method,
                  Names<traits::OutlierMethod>{
                      {"statistical", traits::OutlierMethod::kStatistical},
                      {"voxel_neighbours", traits::OutlierMethod::kVoxelNeighbours},
                  })},
          {"outlier_mean_k", integer(o.outlier_mean_k, 1)},
          {"outlier_stddev_mul", nonNegative(o.outlier_stddev_mul)},
          {"outlier_min_neighbours", integer(o.outlier_min_neighbours, 0, 26)},
          {"crop_z_max_m", positive(o.crop_z_max_m)},
          {"crop_z_min_m", nonNegative(o.crop_z_min_m)},
          {"max_abs_coordinate_m", positive(o.max_abs_coordinate_m)},
          {"template_strip_m", positive(o.template_strip_m)},
          {"template_step_m", positive(o.template_step_m)},
          {"icp_target_leaf_m", positive(o.icp_target_leaf_m)},
          {"icp_coarse_distance_m", positive(o.icp_coarse_distance_m)},
          {"icp_fine_distance_m", nonNegative(o.icp_fine_distance_m)},
          {"icp_iterations", integer(o.icp_iterations, 1)},
          {"max_ground_tilt_deg", numberIn(o.max_ground_tilt_deg, 0, 90)},
          {"max_ground_shift_m", numberIn(o.max_ground_shift_m, 0, 10)},
          {"ground_margin_m", nonNegative(o.ground_margin_m)},
          {"ground_tilt_deg", numberIn(o.ground_tilt_deg, 0, 90, true)},
          {"row_length_m", positive(o.row_length_m)},
          {"crop_to_row_length", flag(o.crop_to_row_length)},
          {"intra_row_spacing_m", positive(o.intra_row_spacing_m)},
          {"slices", integer(o.slices, 0)},
          {"min_row_extent_m", nonNegative(o.min_row_extent_m)},
          {"min_plant_points",
           [&](const Value& v) {
             o.min_plant_points = static_cast<std::size_t>(
                 readIntegerIn(v, 0, std::numeric_limits<std::int64_t>::max()));
           }},
          {"alpha", numberIn(o.alpha, 0, 1, true)},
          {"alpha_near_margin", nonNegative(o.alpha_near_margin)},
          // "paper_mls_gpt" is the name earlier JSON files use.
          {"area_method",
           choice(o.area_method,
                  Names<traits::AreaMethod>{
                      {"depth_map", traits::AreaMethod::kDepthMap},
                      {"paper", traits::AreaMethod::kPaperMlsGpt},
                      {"paper_mls_gpt", traits::AreaMethod::kPaperMlsGpt},
                      {"none", traits::AreaMethod::kNone},
                  })},
          {"depth_map_cell_m", positive(o.depth_map_cell_m)},
          {"depth_map_max_step_m", positive(o.depth_map_max_step_m)},
          {"depth_map_min_fill", numberIn(o.depth_map_min_fill, 0, 1)},
          {"mls_radius_m", positive(o.mls_radius_m)},
          {"gpt_radius_m", positive(o.gpt_radius_m)},
          {"gpt_mu", positive(o.gpt_mu)},
          {"gpt_max_neighbors", integer(o.gpt_max_neighbors, 1)},
      });
  if (!(o.crop_z_min_m < o.crop_z_max_m)) {
    const Value& at = entries.contains("crop_z_min_m") ? entries.at("crop_z_min_m")
                                                       : entryOr(entries, "crop_z_max_m", section);
    at.fail("the depth crop must satisfy crop_z_min_m (" + formatNumber(o.crop_z_min_m) +
            ") < crop_z_max_m (" + formatNumber(o.crop_z_max_m) + ")");
  }
  // The ranges the traits steps are meant for live with the options (TraitsOptions::validate):
  // the same for this file, the JSON of earlier versions and any program that fills them.
  if (const auto problem = o.validate()) {
    if (const auto it = entries.find(problem->key); it != entries.end())
      it->second.fail(problem->message);
    section.fail(problem->key + ": " + problem->message);
  }
}

void readCloud(const Value& section, cloud::CloudOptions& o) {
  const Entries entries =
      readMap(section, {
                           {"scale",
                            [&](const Value& v) {
                              const double scale = v.number();
                              if (!(scale > 0 && scale <= 1))
                                v.fail(v.node().Scalar() + " is out of range (0, 1]");
                              o.scale = scale;
                            }},
                           {"min_depth_m", nonNegative(o.min_depth_m)},
                           {"max_depth_m", positive(o.max_depth_m)},
                           {"edge_max_jump_px", nonNegative(o.edge_max_jump_px)},
                       });
  if (!(o.min_depth_m < o.max_depth_m)) {
    const Value& at = entries.contains("min_depth_m") ? entries.at("min_depth_m")
                                                      : entryOr(entries, "max_depth_m", section);
    at.fail("the depth crop must satisfy min_depth_m (" + formatNumber(o.min_depth_m) +
            ") < max_depth_m (" + formatNumber(o.max_depth_m) + ")");
  }
}

void readPipeline(const Value& section, PipelineConfig& pipeline) {
  readMap(section, {
                       {"enabled", flag(pipeline.enabled)},
                       {"queue_sets",
                        [&](const Value& v) {
                          pipeline.queue_sets =
                              static_cast<std::size_t>(readIntegerIn(v, 1, kMaxPoolSets));
                        }},
                       {"cloud", [&](const Value& v) { readCloud(v, pipeline.cloud); }},
                       {"matcher", [&](const Value& v) { readMatcher(v, pipeline.cloud.matcher); }},
                       {"traits", [&](const Value& v) { readTraits(v, pipeline.traits); }},
                   });
}

void readOutputs(const Value& section, OutputsConfig& outputs) {
  readMap(section, {
                       {"dir", location(outputs.dir)},
                       {"csv", flag(outputs.csv)},
                       {"geojson", flag(outputs.geojson)},
                       {"jsonl", flag(outputs.jsonl)},
                   });
}

void readStatus(const Value& section, StatusConfig& status) {
  readMap(
      section,
      {
          {"enabled", flag(status.enabled)},
          {"address", [&](const Value& v) { status.address = readNonEmptyText(v); }},
          {"port",
           [&](const Value& v) { status.port = static_cast<std::uint16_t>(readInt(v, 0, 65535)); }},
      });
}

void readReplay(const Value& section, ReplayConfig& replay) {
  readMap(section, {
                       {"nmea", location(replay.nmea)},
                       {"realtime", flag(replay.realtime)},
                       {"session", location(replay.session)},
                   });
}

void readLog(const Value& section, LogConfig& log) {
  readMap(section, {
                       {"level",
                        [&](const Value& v) {
                          log.level = std::string(readChoice(v, Names<std::string_view>{
                                                                    {"trace", "trace"},
                                                                    {"debug", "debug"},
                                                                    {"info", "info"},
                                                                    {"warn", "warn"},
                                                                    {"error", "error"},
                                                                }));
                        }},
                       {"file", location(log.file)},
                   });
}

Config readConfig(const Value& root) {
  Config config;
  bool cameras_seen = false;
  readMap(root, {
                    {"gps", [&](const Value& v) { readGps(v, config.gps); }},
                    {"map", location(config.map)},
                    {"cameras",
                     [&](const Value& v) {
                       readCameras(v, config.cameras);
                       cameras_seen = true;
                     }},
                    {"calibration", location(config.calibration)},
                    {"recording", [&](const Value& v) { readRecording(v, config.recording); }},
                    {"pipeline", [&](const Value& v) { readPipeline(v, config.pipeline); }},
                    {"outputs", [&](const Value& v) { readOutputs(v, config.outputs); }},
                    {"status", [&](const Value& v) { readStatus(v, config.status); }},
                    {"replay", [&](const Value& v) { readReplay(v, config.replay); }},
                    {"log", [&](const Value& v) { readLog(v, config.log); }},
                });
  // The rig's cameras are filled from the defaults when the file has no cameras section.
  if (!cameras_seen)
    readCameras(Value(root.source(), YAML::Node(), "cameras", root.mark()), config.cameras);
  return config;
}

// YAML allows no C0 control character but tab and line breaks; yaml-cpp 0.7 loops forever on some
// (a NUL inside a flow map: the config fuzzer found it), so the text is checked before it.
void refuseControlCharacters(const Source& source, const std::string& text) {
  const auto bad = std::find_if(text.begin(), text.end(), [](char c) {
    const auto byte = static_cast<unsigned char>(c);
    return (byte < 0x20 && c != '\t' && c != '\n' && c != '\r') || byte == 0x7f;
  });
  if (bad == text.end())
    return;
  const auto line = 1 + std::count(text.begin(), bad, '\n');
  char code[8];
  std::snprintf(code, sizeof code, "0x%02x",
                static_cast<unsigned>(static_cast<unsigned char>(*bad)));
  throw LoadFailure{source.origin + ":" + std::to_string(line) + ": a control character (" + code +
                    ") in the text; YAML allows none but tab and line breaks"};
}

// Where a document of a text starts, and where its first value does (the line errors name).
class DocumentStarts : public YAML::EventHandler {
 public:
  YAML::Mark start;
  std::optional<YAML::Mark> value;

  void OnDocumentStart(const YAML::Mark& mark) override { start = mark; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { at(mark); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { at(mark); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string&) override {
    at(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    at(mark);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    at(mark);
  }
  void OnMapEnd() override {}

 private:
  void at(const YAML::Mark& mark) {
    if (!value)
      value = mark;
  }
};

// The one document of the text (nothing at all for an empty or comments-only text).
//
// Not YAML::LoadAll: yaml-cpp 0.7's parser yields empty documents at the same place forever after
// a ',' outside a flow collection ("," alone, or "- a\n,"), and LoadAll never returns (the traits
// options fuzzer found it). The documents are counted first, at most three: one that starts where
// the one before it did made no progress and is a syntax error at its line.
YAML::Node parseDocument(const Source& source, const std::string& text) {
  refuseControlCharacters(source, text);
  std::vector<DocumentStarts> documents;
  YAML::Node first;
  try {
    std::istringstream in(text);
    YAML::Parser parser(in);
    while (documents.size() < 3) {
      DocumentStarts document;
      if (!parser.HandleNextDocument(document))
        break;
      if (!documents.empty() && document.start.pos == documents.back().start.pos) {
        throw LoadFailure{source.origin + lineSuffix(document.start) +
                          ": YAML syntax error: text outside any value (a stray ',')"};
      }
      documents.push_back(document);
    }
    if (!documents.empty())
      first = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw LoadFailure{source.origin + lineSuffix(e.mark) + ": YAML syntax error: " + e.msg};
  }
  if (documents.size() > 1) {
    Value(source, YAML::Node(), "", documents[1].value.value_or(documents[1].start))
        .fail("a second YAML document ('---'); one file holds one configuration");
  }
  return first;
}

Value rootValue(const Source& source, const YAML::Node& document) {
  YAML::Mark mark = document.Mark();
  if (mark.is_null())
    mark = YAML::Mark();  // line 0: the file's first line
  const Value root(source, document, "", mark);
  if (!document.IsNull() && !document.IsMap())
    root.fail("expected a map of sections at the top of the file, got " + root.describe());
  return root;
}

// Runs a reader, turning its failure into the Result's error.
template <typename T, typename F>
core::Result<T> guarded(const std::string& origin, F&& read) {
  try {
    return read();
  } catch (const LoadFailure& failure) {
    return core::Error{failure.message};
  } catch (const YAML::Exception& e) {
    return core::Error{origin + lineSuffix(e.mark) + ": " + e.msg};
  }
}

core::Result<std::string> readFile(const fs::path& file) {
  std::error_code ec;
  if (fs::is_directory(file, ec))
    return core::Error{file.string() + ": cannot open: it is a folder"};
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    const int error = errno;
    return core::Error{file.string() + ": cannot open: " +
                       std::error_code(error, std::generic_category()).message()};
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad())
    return core::Error{file.string() + ": cannot read: " +
                       std::error_code(errno, std::generic_category()).message()};
  return text.str();
}

// The folder relative paths of `file` are taken against.
fs::path folderOf(const fs::path& file) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(file, ec);
  return (ec ? file : absolute).parent_path().lexically_normal();
}

}  // namespace

core::Result<Config> parseConfig(const std::string& text, const std::string& origin,
                                 const std::filesystem::path& base_dir) {
  const Source source{origin, base_dir};
  return guarded<Config>(origin, [&] {
    Config config = readConfig(rootValue(source, parseDocument(source, text)));
    config.source = origin;
    return config;
  });
}

core::Result<Config> loadConfig(const std::filesystem::path& file) {
  core::Result<std::string> text = readFile(file);
  if (!text)
    return text.error();
  core::Result<Config> config = parseConfig(*text, file.string(), folderOf(file));
  if (config)
    config->source = file;
  return config;
}

core::Result<traits::TraitsOptions> loadTraitsOptions(const std::filesystem::path& file) {
  core::Result<std::string> text = readFile(file);
  if (!text)
    return text.error();
  const Source source{file.string(), folderOf(file)};
  return guarded<traits::TraitsOptions>(source.origin, [&] {
    traits::TraitsOptions options;
    readTraits(rootValue(source, parseDocument(source, *text)), options);
    return options;
  });
}

}  // namespace fieldrig::config
