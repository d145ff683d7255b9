// `fieldrig map generate` and `fieldrig map record`, run as the built binary.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/LocalCartesian.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "fieldrig/gps/field_plan.h"
#include "fieldrig/gps/location_map.h"

namespace fieldrig {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using Json = nlohmann::json;

const std::string kBinary = FIELDRIG_BINARY_DIR "/tools/fieldrig";

// A child process with pipes on stdin, stdout and stderr.
class Child {
 public:
  explicit Child(const std::vector<std::string>& args) {
    int in_pipe[2], out_pipe[2], err_pipe[2];
    if (::pipe(in_pipe) != 0 || ::pipe(out_pipe) != 0 || ::pipe(err_pipe) != 0)
      throw std::runtime_error("pipe");
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(in_pipe[0], STDIN_FILENO);
      ::dup2(out_pipe[1], STDOUT_FILENO);
      ::dup2(err_pipe[1], STDERR_FILENO);
      for (int fd : {in_pipe[0], in_pipe[1], out_pipe[0], out_pipe[1], err_pipe[0], err_pipe[1]})
        ::close(fd);
      std::vector<char*> argv;
      argv.push_back(const_cast<char*>(kBinary.c_str()));
      for (const std::string& arg : args)
        argv.push_back(const_cast<char*>(arg.c_str()));
      argv.push_back(nullptr);
      ::execv(kBinary.c_str(), argv.data());
      ::_exit(127);
    }
    ::close(in_pipe[0]);
    ::close(out_pipe[1]);
    ::close(err_pipe[1]);
    stdin_ = in_pipe[1];
    stdout_ = out_pipe[0];
    stderr_ = err_pipe[0];
  }

  ~Child() {
    if (pid_ > 0 && !exited_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    for (int fd : {stdin_, stdout_, stderr_}) {
      if (fd >= 0)
        ::close(fd);
    }
  }

  pid_t pid() const { return pid_; }
  void send(std::string_view text) {
    ASSERT_EQ(::write(stdin_, text.data(), text.size()), static_cast<ssize_t>(text.size()));
  }

  // Collects output until `done` holds or the timeout passes; returns whether `done` held.
  template <typename Predicate>
  bool pumpUntil(Predicate done, std::chrono::milliseconds timeout) {
    const auto deadline = Clock::now() + timeout;
    while (!done()) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
      if (left.count() <= 0)
        return false;
      pollfd fds[2] = {{stdout_, POLLIN, 0}, {stderr_, POLLIN, 0}};
      if (::poll(fds, 2, static_cast<int>(std::min<long>(left.count(), 50))) < 0)
        return false;
      bool progress = false;
      for (int i = 0; i < 2; ++i) {
        if (fds[i].revents == 0)
          continue;
        char buffer[4096];
        const ssize_t n = ::read(fds[i].fd, buffer, sizeof buffer);
        if (n > 0) {
          (i == 0 ? out : err).append(buffer, static_cast<std::size_t>(n));
          progress = true;
        }
      }
      if (!progress && exited_)
        return done();
      if (!progress)
        reap();
    }
    return true;
  }

  bool waitForStderr(std::string_view needle, std::chrono::milliseconds timeout = 10s) {
    return pumpUntil([&] { return err.find(needle) != std::string::npos; }, timeout);
  }
  bool waitForStdoutLines(std::size_t lines, std::chrono::milliseconds timeout = 10s) {
    return pumpUntil(
        [&] { return static_cast<std::size_t>(std::count(out.begin(), out.end(), '\n')) >= lines; },
        timeout);
  }

  // Waits for the exit (collecting output); the exit code, or -1 on timeout or a signal.
  int waitExit(std::chrono::milliseconds timeout = 20s) {
    pumpUntil([&] { return exited_ && drained(); }, timeout);
    if (!exited_)
      return -1;
    return WIFEXITED(status_) ? WEXITSTATUS(status_) : -1;
  }

  std::vector<Json> stdoutJson() const {
    std::vector<Json> lines;
    std::istringstream in(out);
    std::string line;
    while (std::getline(in, line))
      lines.push_back(Json::parse(line));
    return lines;
  }

  std::string out;
  std::string err;

 private:
  void reap() {
    if (!exited_ && ::waitpid(pid_, &status_, WNOHANG) == pid_)
      exited_ = true;
  }
  bool drained() {
    pollfd fds[2] = {{stdout_, POLLIN, 0}, {stderr_, POLLIN, 0}};
    ::poll(fds, 2, 0);
    // After the exit, an empty read (POLLHUP without data) means all output is in.
    for (auto& fd : fds) {
      if (fd.revents & POLLIN)
        return false;
    }
    return true;
  }

  pid_t pid_ = -1;
  int stdin_ = -1, stdout_ = -1, stderr_ = -1;
  int status_ = 0;
  bool exited_ = false;
};

// Runs the binary to completion with empty stdin.
int runToEnd(const std::vector<std::string>& args, std::string* out, std::string* err) {
  Child child(args);
  child.send("");
  const int code = child.waitExit();
  if (out)
    *out = child.out;
  if (err)
    *err = child.err;
  return code;
}

class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("fieldrig_map_cli_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string operator/(const std::string& file) const { return (path_ / file).string(); }

 private:
  std::filesystem::path path_;
};

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// ---------------------------------------------------------------------------------------------
// Synthetic NMEA.

std::string withChecksum(const std::string& body) {
  unsigned char sum = 0;
  for (char c : body)
    sum ^= static_cast<unsigned char>(c);
  char tail[8];
  std::snprintf(tail, sizeof tail, "*%02X\r\n", sum);
  return "$" + body + tail;
}

// NMEA's dddmm.mmmmmmmm, rounded as a whole so that 41.99999999999 becomes 4200.00000000, not
// 4159.99999999 rounded to the invalid 4160.00000000.
std::string angle(double degrees, int degree_digits, char positive, char negative) {
  const auto units = static_cast<long long>(std::llround(std::fabs(degrees) * 60.0 * 1e8));
  const long long per_degree = 60LL * 100'000'000LL;
  const long long whole = units / per_degree;
  const long long minutes = (units % per_degree) / 100'000'000LL;
  const long long fraction = units % 100'000'000LL;
  char text[48];
  std::snprintf(text, sizeof text, "%0*lld%02lld.%08lld,%c", degree_digits, whole, minutes,
                fraction, degrees < 0 ? negative : positive);
  return text;
}

struct Epoch {
  double t = 0;  // seconds after 15:30:00 UTC, 2026-07-14
  double latitude = 0;
  double longitude = 0;
  bool valid = true;
  double speed_mps = 0;
  std::optional<double> course;
};

std::string timeOfDay(double t) {
  // Seconds below 60 only: the drives here are short.
  const int hundredths = static_cast<int>(std::lround(t * 100)) % 6000;
  char text[32];
  std::snprintf(text, sizeof text, "1530%02d.%02d", hundredths / 100, hundredths % 100);
  return text;
}

std::string nmeaFor(const Epoch& e) {
  char speed[32];
  std::snprintf(speed, sizeof speed, "%.4f", e.speed_mps / (1852.0 / 3600.0));
  char course[32] = "";
  if (e.course)
    std::snprintf(course, sizeof course, "%.2f", *e.course);
  const std::string position =
      angle(e.latitude, 2, 'N', 'S') + "," + angle(e.longitude, 3, 'E', 'W');
  const std::string rmc = "GPRMC," + timeOfDay(e.t) + "," + (e.valid ? "A" : "V") + "," + position +
                          "," + speed + "," + course + ",140726,,," + (e.valid ? "D" : "N");
  const std::string gga = "GPGGA," + timeOfDay(e.t) + "," + position + "," + (e.valid ? "4" : "0") +
                          ",12,0.8,300.0,M,-30.0,M,,";
  return withChecksum(rmc) + withChecksum(gga);
}

// The driven track in a local east/north frame near Ames, Iowa.
struct Track {
  GeographicLib::LocalCartesian frame{42.0, -93.6, 0.0};

  Epoch at(double t, double east, double north) const {
    Epoch e;
    e.t = t;
    double h = 0;
    frame.Reverse(east, north, 0.0, e.latitude, e.longitude, h);
    return e;
  }
  void local(double latitude, double longitude, double& east, double& north) const {
    double up = 0;
    frame.Forward(latitude, longitude, 0.0, east, north, up);
  }
};

// Distance along and across a leg from `start` on `heading_deg`.
void legCoordinates(double east, double north, double start_east, double start_north,
                    double heading_deg, double& along, double& across) {
  const double rad = heading_deg * std::numbers::pi / 180.0;
  const double ue = std::sin(rad), un = std::cos(rad);
  along = (east - start_east) * ue + (north - start_north) * un;
  across = (east - start_east) * un - (north - start_north) * ue;
}

void writeFile(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// ---------------------------------------------------------------------------------------------
// map generate

TEST(MapCli, GenerateWritesTheFieldPlansMap) {
  TempDir dir("generate");
  std::string out, err;
  const int code = runToEnd({"map",
                             "generate",
                             "--row-start",
                             "42.0105,-93.7452",
                             "--row-end",
                             "42.0110,-93.7445",
                             "--rows",
                             "3",
                             "--plots",
                             "4",
                             "--plot-length",
                             "3.048",
                             "--alley-length",
                             "1.0",
                             "--row-spacing",
                             "2.286",
                             "--start-offset",
                             "0.5",
                             "--left",
                             "--id-prefix",
                             "T",
                             "--out",
                             dir / "map.csv"},
                            &out, &err);
  ASSERT_EQ(code, 0) << err;
  const Json summary = Json::parse(out);
  EXPECT_EQ(summary["locations"], 12);
  EXPECT_EQ(summary["rows"], 3);
  EXPECT_EQ(summary["plots_per_row"], 4);

  gps::FieldPlan plan;
  plan.row_start_latitude_deg = 42.0105;
  plan.row_start_longitude_deg = -93.7452;
  plan.row_end_latitude_deg = 42.0110;
  plan.row_end_longitude_deg = -93.7445;
  plan.rows = 3;
  plan.plots_per_row = 4;
  plan.plot_length_m = 3.048;
  plan.alley_length_m = 1.0;
  plan.row_spacing_m = 2.286;
  plan.start_offset_m = 0.5;
  plan.rows_to_the_right = false;
  plan.id_prefix = "T";
  auto expected = gps::generateLocations(plan);
  ASSERT_TRUE(expected.ok()) << expected.error().message;
  auto written = gps::LocationMap::load(dir / "map.csv");
  ASSERT_TRUE(written.ok()) << written.error().message;
  ASSERT_EQ(written->size(), 12u);
  EXPECT_EQ(written->metadataColumns(), expected->metadataColumns());
  for (std::size_t i = 0; i < written->size(); ++i) {
    const auto& a = written->locations()[i];
    const auto& b = expected->locations()[i];
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.latitude_deg, b.latitude_deg);
    EXPECT_EQ(a.longitude_deg, b.longitude_deg);
    EXPECT_EQ(a.heading_deg, b.heading_deg);
    EXPECT_EQ(a.metadata, b.metadata);
  }
  EXPECT_EQ(written->locations()[4].id, "TR02P04");  // serpentine: row 2 starts at its far end
}

TEST(MapCli, GenerateRejectsABadPlan) {
  TempDir dir("generate_bad");
  std::string err;
  EXPECT_EQ(runToEnd({"map", "generate", "--row-start", "42.0105,-93.7452", "--row-end",
                      "42.0110,-93.7445", "--rows", "0", "--plot-length", "3", "--alley-length",
                      "1", "--row-spacing", "2", "--out", dir / "map.csv"},
                     nullptr, &err),
            2);
  EXPECT_NE(err.find("field 'rows'"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(dir / "map.csv"));
  EXPECT_EQ(runToEnd({"map", "generate", "--row-start", "42.0105;-93.7452", "--row-end",
                      "42.0110,-93.7445", "--rows", "1", "--plot-length", "3", "--alley-length",
                      "1", "--row-spacing", "2", "--out", dir / "map.csv"},
                     nullptr, &err),
            2);
  EXPECT_NE(err.find("--row-start"), std::string::npos) << err;
}

// ---------------------------------------------------------------------------------------------
// map record

// Invalid fixes until 1.2 s; leg 1 north-east (45 degrees) at 2 m/s with RMC course until
// 3.5 s; leg 2 south-east (135 degrees) at 2 m/s without RMC course until 6 s.
constexpr double kLeg1Start = 1.2, kLeg2Start = 3.5, kEnd = 6.0;

std::string twoLegDrive(const Track& track, double& corner_east, double& corner_north) {
  const double rad45 = std::numbers::pi / 4;
  corner_east = 2.0 * (kLeg2Start - kLeg1Start) * std::sin(rad45);
  corner_north = 2.0 * (kLeg2Start - kLeg1Start) * std::cos(rad45);
  std::string nmea = "$GPGSV,garbage line the parser must survive\r\n";
  for (int i = 0; i <= static_cast<int>(kEnd * 10 + 0.5); ++i) {
    const double t = i / 10.0;
    Epoch e;
    if (t < kLeg1Start) {
      e = track.at(t, 0, 0);
      e.valid = false;
    } else if (t < kLeg2Start) {
      const double s = 2.0 * (t - kLeg1Start);
      e = track.at(t, s * std::sin(rad45), s * std::cos(rad45));
      e.speed_mps = 2.0;
      e.course = 45.0;
    } else {
      const double s = 2.0 * (t - kLeg2Start);
      e = track.at(t, corner_east + s * std::sin(3 * rad45),
                   corner_north + s * std::cos(3 * rad45));
      e.speed_mps = 2.0;
    }
    nmea += nmeaFor(e);
  }
  return nmea;
}

TEST(MapCli, RecordFromFileMarksByEnterAndSigusr1) {
  TempDir dir("record");
  Track track;
  double corner_east = 0, corner_north = 0;
  writeFile(dir / "drive.nmea", twoLegDrive(track, corner_east, corner_north));

  Child child(
      {"map", "record", "--nmea", dir / "drive.nmea", "--out", dir / "map.csv", "--realtime"});
  ASSERT_TRUE(child.waitForStderr("mark with Enter")) << child.err;
  const auto start = Clock::now();
  // Before any valid fix: refused, nothing written.
  std::this_thread::sleep_until(start + 400ms);
  child.send("\n");
  ASSERT_TRUE(child.waitForStderr("refused")) << child.err;
  // On leg 1, by Enter.
  std::this_thread::sleep_until(start + 2300ms);
  child.send("\n");
  ASSERT_TRUE(child.waitForStdoutLines(1)) << child.err;
  // On leg 2, by SIGUSR1.
  std::this_thread::sleep_until(start + 5000ms);
  ASSERT_EQ(::kill(child.pid(), SIGUSR1), 0);
  ASSERT_TRUE(child.waitForStdoutLines(2)) << child.err;
  // The file ends at 6 s, and so does the command.
  ASSERT_EQ(child.waitExit(), 0) << child.err;
  EXPECT_NE(child.err.find("2 marks written"), std::string::npos) << child.err;

  const std::vector<Json> marks = child.stdoutJson();
  ASSERT_EQ(marks.size(), 2u) << child.out;
  EXPECT_EQ(marks[0]["id"], "P1");
  EXPECT_EQ(marks[0]["trigger"], "enter");
  EXPECT_EQ(marks[0]["heading_source"], "course");
  EXPECT_EQ(marks[1]["id"], "P2");
  EXPECT_EQ(marks[1]["trigger"], "sigusr1");
  EXPECT_EQ(marks[1]["heading_source"], "track");

  auto map = gps::LocationMap::load(dir / "map.csv");
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_EQ(map->size(), 2u);
  EXPECT_EQ(map->metadataColumns(), (std::vector<std::string>{"time", "speed_mps", "quality"}));

  // P1 lies on leg 1 (within the 8-decimal NMEA rounding), heading its course.
  const gps::ImagingLocation& p1 = map->locations()[0];
  EXPECT_EQ(p1.latitude_deg, marks[0]["lat"].get<double>());
  double east = 0, north = 0, along = 0, across = 0;
  track.local(p1.latitude_deg, p1.longitude_deg, east, north);
  legCoordinates(east, north, 0, 0, 45.0, along, across);
  EXPECT_LT(std::fabs(across), 0.001);
  EXPECT_GT(along, 0.0);
  EXPECT_LT(along, 2.0 * (kLeg2Start - kLeg1Start));
  ASSERT_TRUE(p1.heading_deg.has_value());
  EXPECT_DOUBLE_EQ(*p1.heading_deg, 45.0);
  EXPECT_EQ(p1.metadata[1], "2.000");
  EXPECT_EQ(p1.metadata[2], "4");
  EXPECT_EQ(p1.metadata[0].rfind("2026-07-14T15:30:0", 0), 0u) << p1.metadata[0];

  // P2 lies on leg 2; its heading is the bearing of the track behind it (no RMC course).
  const gps::ImagingLocation& p2 = map->locations()[1];
  track.local(p2.latitude_deg, p2.longitude_deg, east, north);
  legCoordinates(east, north, corner_east, corner_north, 135.0, along, across);
  EXPECT_LT(std::fabs(across), 0.001);
  // Far enough into leg 2 that the 1 m bearing base is all on leg 2 (the mark came ~1.5 s in).
  EXPECT_GT(along, 1.2);
  EXPECT_LE(along, 2.0 * (kEnd - kLeg2Start) + 1e-3);
  ASSERT_TRUE(p2.heading_deg.has_value());
  EXPECT_NEAR(*p2.heading_deg, 135.0, 0.01);
}

TEST(MapCli, RecordContinuesAnExistingMapAndRefusesStaleFixes) {
  TempDir dir("record_continue");
  const std::string header = "id,lat,lon,heading,time,speed_mps,quality\n";
  const std::string existing = "# recorded yesterday\n" + header +
                               "P7,42.001,-93.601,10,2026-07-13T15:00:00.000Z,1.500,4\n"
                               "X1,42.002,-93.602,,2026-07-13T15:00:01.000Z,,";  // no final newline
  writeFile(dir / "map.csv", existing);

  // Valid fixes heading north for 1.5 s, then nothing until a last fix at 6 s.
  Track track;
  std::string nmea;
  for (int i = 0; i <= 15; ++i) {
    Epoch e = track.at(i / 10.0, 0, 1.5 * i / 10.0);
    e.speed_mps = 1.5;
    e.course = 0.0;
    nmea += nmeaFor(e);
  }
  Epoch last = track.at(6.0, 0, 10.0);
  last.speed_mps = 1.5;
  nmea += nmeaFor(last);
  writeFile(dir / "drive.nmea", nmea);

  Child child({"map", "record", "--nmea", dir / "drive.nmea", "--out", dir / "map.csv"});
  ASSERT_TRUE(child.waitForStderr("mark with Enter")) << child.err;
  EXPECT_NE(child.err.find("2 locations already there"), std::string::npos) << child.err;
  const auto start = Clock::now();
  std::this_thread::sleep_until(start + 700ms);
  child.send("\n");
  ASSERT_TRUE(child.waitForStdoutLines(1)) << child.err;
  // 4.2 s: the latest fix (1.5 s) is 2.7 s old.
  std::this_thread::sleep_until(start + 4200ms);
  child.send("\n");
  ASSERT_TRUE(child.waitForStderr("s old; nothing written")) << child.err;
  ASSERT_EQ(child.waitExit(), 0) << child.err;

  const std::vector<Json> marks = child.stdoutJson();
  ASSERT_EQ(marks.size(), 1u) << child.out;
  EXPECT_EQ(marks[0]["id"], "P8");  // one past the highest P number

  const std::string text = readFile(dir / "map.csv");
  // The old text is kept byte for byte, the missing newline added, the header not repeated.
  ASSERT_EQ(text.rfind(existing + "\n", 0), 0u) << text;
  EXPECT_EQ(text.find(header), text.rfind(header));
  auto map = gps::LocationMap::load(dir / "map.csv");
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_EQ(map->size(), 3u);
  const gps::ImagingLocation& p8 = map->locations()[2];
  EXPECT_EQ(p8.id, "P8");
  double east = 0, north = 0;
  track.local(p8.latitude_deg, p8.longitude_deg, east, north);
  EXPECT_LT(std::fabs(east), 0.001);
  EXPECT_GT(north, 0.0);
  EXPECT_LE(north, 1.5 * 1.5 + 1e-3);
  EXPECT_EQ(p8.heading_deg, std::optional<double>(0.0));
}

TEST(MapCli, RecordRefusesAnIncompatibleExistingMap) {
  TempDir dir("record_incompatible");
  writeFile(dir / "drive.nmea", nmeaFor(Track{}.at(0, 0, 0)));
  const std::string other = "id,lat,lon,plot\nA,42,-93,1\n";
  writeFile(dir / "map.csv", other);
  std::string err;
  EXPECT_EQ(runToEnd({"map", "record", "--nmea", dir / "drive.nmea", "--out", dir / "map.csv"},
                     nullptr, &err),
            2);
  EXPECT_NE(err.find("is not the recording header"), std::string::npos) << err;
  EXPECT_EQ(readFile(dir / "map.csv"), other);

  // A broken map is reported with its line.
  writeFile(dir / "map.csv", "id,lat,lon,heading,time,speed_mps,quality\nA,95,-93,,,,\n");
  EXPECT_EQ(runToEnd({"map", "record", "--nmea", dir / "drive.nmea", "--out", dir / "map.csv"},
                     nullptr, &err),
            2);
  EXPECT_NE(err.find("map.csv:2: field 'lat': 95 is outside"), std::string::npos) << err;
}

TEST(MapCli, RecordFromAFifo) {
  TempDir dir("record_fifo");
  const std::string fifo = dir / "gps.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  Child child({"map", "record", "--nmea", fifo, "--out", dir / "map.csv", "--id-prefix", "F",
               "--start-id", "100"});
  const int writer = ::open(fifo.c_str(), O_WRONLY);  // meets the recorder's open
  ASSERT_GE(writer, 0);
  ASSERT_TRUE(child.waitForStderr("mark with Enter")) << child.err;
  Track track;
  std::string nmea;
  for (int i = 0; i < 10; ++i) {
    Epoch e = track.at(i / 10.0, -0.5 * i / 10.0, 0);  // due west at 0.5 m/s
    e.speed_mps = 0.5;
    e.course = 270.0;
    nmea += nmeaFor(e);
  }
  ASSERT_EQ(::write(writer, nmea.data(), nmea.size()), static_cast<ssize_t>(nmea.size()));
  std::this_thread::sleep_for(300ms);
  child.send("\n");
  ASSERT_TRUE(child.waitForStdoutLines(1)) << child.err;
  ::close(writer);  // end of input ends the command
  ASSERT_EQ(child.waitExit(), 0) << child.err;
  const std::vector<Json> marks = child.stdoutJson();
  ASSERT_EQ(marks.size(), 1u);
  EXPECT_EQ(marks[0]["id"], "F100");
  EXPECT_EQ(marks[0]["heading_deg"], 270.0);
  // The last fix written before the mark: 0.45 m west of the start.
  double east = 0, north = 0;
  track.local(marks[0]["lat"].get<double>(), marks[0]["lon"].get<double>(), east, north);
  EXPECT_NEAR(east, -0.45, 0.001);
  EXPECT_NEAR(north, 0.0, 0.001);
}

// Through a real pseudo-terminal pair, as from the receiver's serial port.
TEST(MapCli, RecordFromASerialPty) {
  if (::access("/usr/bin/socat", X_OK) != 0)
    GTEST_SKIP() << "socat is not installed";
  TempDir dir("record_pty");
  const std::string device = dir / "gps", feed = dir / "feed";
  const pid_t socat = ::fork();
  if (socat == 0) {
    const std::string a = "pty,raw,echo=0,link=" + device, b = "pty,raw,echo=0,link=" + feed;
    ::execl("/usr/bin/socat", "socat", a.c_str(), b.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  struct KillSocat {
    pid_t pid;
    ~KillSocat() {
      ::kill(pid, SIGTERM);
      ::waitpid(pid, nullptr, 0);
    }
  } kill_socat{socat};
  const auto deadline = Clock::now() + 5s;
  while (!(std::filesystem::exists(device) && std::filesystem::exists(feed)) &&
         Clock::now() < deadline) {
    std::this_thread::sleep_for(20ms);
  }
  ASSERT_TRUE(std::filesystem::exists(device) && std::filesystem::exists(feed));

  Child child({"map", "record", "--nmea", device, "--out", dir / "map.csv", "--baud", "38400"});
  ASSERT_TRUE(child.waitForStderr("mark with Enter")) << child.err;
  const int writer = ::open(feed.c_str(), O_WRONLY | O_NOCTTY);
  ASSERT_GE(writer, 0);
  Track track;
  const auto start = Clock::now();
  bool marked = false;
  for (int i = 0; i < 20; ++i) {
    std::this_thread::sleep_until(start + i * 100ms);
    Epoch e = track.at(i / 10.0, 0, -1.0 * i / 10.0);  // due south at 1 m/s
    e.speed_mps = 1.0;
    e.course = 180.0;
    const std::string text = nmeaFor(e);
    ASSERT_EQ(::write(writer, text.data(), text.size()), static_cast<ssize_t>(text.size()));
    if (i == 12) {
      std::this_thread::sleep_for(30ms);  // let the epoch arrive before the mark
      child.send("\n");
      marked = true;
    }
  }
  ASSERT_TRUE(marked);
  ASSERT_TRUE(child.waitForStdoutLines(1)) << child.err;
  ::kill(child.pid(), SIGINT);
  ASSERT_EQ(child.waitExit(), 0) << child.err;
  ::close(writer);

  const std::vector<Json> marks = child.stdoutJson();
  ASSERT_EQ(marks.size(), 1u);
  EXPECT_EQ(marks[0]["id"], "P1");
  EXPECT_EQ(marks[0]["heading_deg"], 180.0);
  double east = 0, north = 0;
  track.local(marks[0]["lat"].get<double>(), marks[0]["lon"].get<double>(), east, north);
  EXPECT_NEAR(east, 0.0, 0.001);
  // Epoch 12 (1.2 m south), give or take one epoch of scheduling.
  EXPECT_NEAR(north, -1.2, 0.1 + 1e-3);
  auto map = gps::LocationMap::load(dir / "map.csv");
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map->size(), 1u);
}

}  // namespace
}  // namespace fieldrig
