#include "nmea_player.h"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <sstream>

#include "fieldrig/core/durable_file.h"
#include "fieldrig/gps/nmea_parser.h"

namespace fieldrig::daemon {
namespace {

constexpr auto kDay = std::chrono::hours{24};

// The time of day an RMC or GGA line carries; nullopt for other lines.
std::optional<core::Nanoseconds> timeOfDay(std::string_view line) {
  const gps::Sentence sentence = gps::NmeaParser::parseLine(line);
  if (sentence.kind == gps::SentenceKind::kRmc)
    return sentence.rmc.time_of_day;
  if (sentence.kind == gps::SentenceKind::kGga)
    return sentence.gga.time_of_day;
  return std::nullopt;
}

}  // namespace

core::Result<std::unique_ptr<NmeaPlayer>> NmeaPlayer::start(const std::filesystem::path& file,
                                                            std::function<void()> on_end) {
  std::string error;
  std::optional<std::string> content = core::readWholeFile(file, error);
  if (!content)
    return core::Error{error};
  std::unique_ptr<NmeaPlayer> player(new NmeaPlayer());
  player->master_fd_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (player->master_fd_ < 0 || ::grantpt(player->master_fd_) != 0 ||
      ::unlockpt(player->master_fd_) != 0) {
    return core::Error{std::string("replay: cannot create a pseudo-terminal: ") +
                       std::strerror(errno)};
  }
  const char* name = ::ptsname(player->master_fd_);
  if (name == nullptr)
    return core::Error{std::string("replay: ptsname: ") + std::strerror(errno)};
  player->device_ = name;
  player->slave_fd_ = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (player->slave_fd_ >= 0) {
    termios raw{};
    if (::tcgetattr(player->slave_fd_, &raw) == 0) {
      ::cfmakeraw(&raw);
      ::tcsetattr(player->slave_fd_, TCSANOW, &raw);
    }
  }
  player->on_end_ = std::move(on_end);
  NmeaPlayer* raw_player = player.get();
  player->thread_ = std::thread(
      [raw_player, text = std::move(*content)]() mutable { raw_player->play(std::move(text)); });
  return player;
}

NmeaPlayer::~NmeaPlayer() {
  stop_ = true;
  if (thread_.joinable())
    thread_.join();
  if (slave_fd_ >= 0)
    ::close(slave_fd_);
  if (master_fd_ >= 0)
    ::close(master_fd_);
}

void NmeaPlayer::play(std::string content) {
  // Give the reader a moment to open the device before the first epoch.
  std::this_thread::sleep_for(std::chrono::milliseconds{300});
  const auto start = std::chrono::steady_clock::now();
  std::optional<core::Nanoseconds> first;
  core::Nanoseconds day_offset{0};
  core::Nanoseconds previous{0};
  std::istringstream lines(content);
  std::string line;
  while (!stop_ && std::getline(lines, line)) {
    if (!line.empty() && line.back() == '\r')
      line.pop_back();
    if (const auto tod = timeOfDay(line)) {
      core::Nanoseconds t = *tod + day_offset;
      if (first && t + std::chrono::hours{12} < previous) {  // past midnight
        day_offset += kDay;
        t += kDay;
      }
      if (!first)
        first = t;
      previous = t;
      const auto due = start + (t - *first);
      while (!stop_ && std::chrono::steady_clock::now() < due)
        std::this_thread::sleep_for(std::min<std::chrono::steady_clock::duration>(
            due - std::chrono::steady_clock::now(), std::chrono::milliseconds{50}));
    }
    line += "\r\n";
    if (core::writeFully(master_fd_, line.data(), line.size()) != 0)
      break;
  }
  if (!stop_) {
    std::this_thread::sleep_for(std::chrono::milliseconds{500});  // the last fixes' triggers
    if (on_end_)
      on_end_();
  }
}

}  // namespace fieldrig::daemon
