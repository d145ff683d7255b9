#include "fieldrig/sim/nmea_player.h"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <spdlog/spdlog.h>
#include <boost/asio/post.hpp>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <utility>

#include "fieldrig/core/durable_file.h"
#include "fieldrig/gps/nmea_parser.h"

namespace fieldrig::sim {
namespace {

namespace asio = boost::asio;

// The pty's reader (the daemon's serial source) opens the device after the player started:
// the first epoch waits for it.
constexpr std::chrono::milliseconds kReaderHeadStart{300};
// After the last line, the time the reader needs to read it and fire its last triggers.
constexpr std::chrono::milliseconds kLastFixesTime{500};

}  // namespace

// ---- NmeaPacer -------------------------------------------------------------------------------

core::Nanoseconds NmeaPacer::waitBefore(std::string_view line) {
  if (!line.empty() && line.back() == '\r')
    line.remove_suffix(1);
  const std::optional<core::GpsFix> fix =
      assembler_.add(gps::NmeaParser::parseLine(line), core::ReceptionStamp{});
  if (!fix)
    return core::Nanoseconds{0};
  if (!last_time_ || fix->time <= *last_time_) {
    last_time_ = fix->time;
    return core::Nanoseconds{0};
  }
  core::Nanoseconds wait = fix->time - *last_time_;
  if (max_gap_)
    wait = std::min(wait, *max_gap_);
  last_time_ = fix->time;
  return wait;
}

// ---- NmeaPlayer ------------------------------------------------------------------------------

core::Result<std::unique_ptr<NmeaPlayer>> NmeaPlayer::open(boost::asio::io_context& io,
                                                           const std::filesystem::path& path,
                                                           NmeaPacing pacing, BytesHandler on_bytes,
                                                           std::function<void()> on_end) {
  std::unique_ptr<NmeaPlayer> player(
      new NmeaPlayer(io, pacing, std::move(on_bytes), std::move(on_end)));
  std::error_code error;
  const std::filesystem::file_type type = std::filesystem::status(path, error).type();
  if (type == std::filesystem::file_type::fifo) {
    // Blocks until a writer opens the FIFO, which is what a reader of a FIFO wants.
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0)
      return core::Error{path.string() + ": cannot open: " + std::strerror(errno)};
    player->stream_.emplace(io, fd);
    return player;
  }
  if (type != std::filesystem::file_type::regular && !error) {
    return core::Error{path.string() + ": not a file or FIFO"};
  }
  player->file_.open(path, std::ios::binary);
  if (!player->file_)
    return core::Error{path.string() + ": cannot open: " + std::strerror(errno)};
  return player;
}

NmeaPlayer::NmeaPlayer(boost::asio::io_context& io, NmeaPacing pacing, BytesHandler on_bytes,
                       std::function<void()> on_end)
    : io_(io),
      pacing_(pacing),
      on_bytes_(std::move(on_bytes)),
      on_end_(std::move(on_end)),
      timer_(io),
      pacer_(pacing.max_gap) {}

NmeaPlayer::~NmeaPlayer() {
  stop();
}

void NmeaPlayer::start() {
  deadline_ = std::chrono::steady_clock::now();
  asio::post(io_, [this, alive = std::weak_ptr<char>(alive_)] {
    if (alive.expired() || stopped_)
      return;
    if (stream_)
      readStream();
    else
      playFile();
  });
}

void NmeaPlayer::stop() {
  stopped_ = true;
  timer_.cancel();
  if (stream_) {
    boost::system::error_code ignored;
    stream_->cancel(ignored);
  }
}

void NmeaPlayer::playFile() {
  if (!pacing_.realtime) {
    // A chunk per turn of the loop, so that the io_context's other work is served in between.
    file_.read(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    const auto count = static_cast<std::size_t>(file_.gcount());
    if (count == 0)
      return end();
    on_bytes_(std::string_view(buffer_.data(), count));
    asio::post(io_, [this, alive = std::weak_ptr<char>(alive_)] {
      if (!alive.expired() && !stopped_)
        playFile();
    });
    return;
  }
  while (!stopped_) {
    if (!pending_) {
      std::string line;
      if (!std::getline(file_, line))
        return end();
      if (!line.empty() && line.back() == '\r')
        line.pop_back();
      const core::Nanoseconds wait = pacer_.waitBefore(line);
      pending_ = std::move(line) + "\r\n";
      if (wait > core::Nanoseconds{0}) {
        // Due times add up from the start, so the delays of the io loop never accumulate.
        deadline_ += std::chrono::duration_cast<std::chrono::steady_clock::duration>(wait);
        timer_.expires_at(deadline_);
        timer_.async_wait(
            [this, alive = std::weak_ptr<char>(alive_)](const boost::system::error_code& error) {
              if (!error && !alive.expired() && !stopped_)
                playFile();
            });
        return;
      }
    }
    on_bytes_(*pending_);
    pending_.reset();
  }
}

void NmeaPlayer::readStream() {
  stream_->async_read_some(asio::buffer(buffer_),
                           [this, alive = std::weak_ptr<char>(alive_)](
                               const boost::system::error_code& error, std::size_t bytes) {
                             if (alive.expired() || stopped_)
                               return;
                             if (bytes > 0)
                               on_bytes_(std::string_view(buffer_.data(), bytes));
                             if (stopped_)
                               return;
                             if (error)
                               return end();
                             readStream();
                           });
}

void NmeaPlayer::end() {
  if (stopped_)
    return;
  stopped_ = true;
  if (on_end_)
    on_end_();
}

// ---- NmeaPtyPlayer ---------------------------------------------------------------------------

core::Result<std::unique_ptr<NmeaPtyPlayer>> NmeaPtyPlayer::start(const std::filesystem::path& file,
                                                                  NmeaPacing pacing,
                                                                  std::function<void()> on_end) {
  std::unique_ptr<NmeaPtyPlayer> pty(new NmeaPtyPlayer());
  pty->master_fd_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (pty->master_fd_ < 0 || ::grantpt(pty->master_fd_) != 0 || ::unlockpt(pty->master_fd_) != 0) {
    return core::Error{std::string("NMEA player: cannot create a pseudo-terminal: ") +
                       std::strerror(errno)};
  }
  const char* name = ::ptsname(pty->master_fd_);
  if (name == nullptr)
    return core::Error{std::string("NMEA player: ptsname: ") + std::strerror(errno)};
  pty->device_ = name;
  pty->slave_fd_ = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (pty->slave_fd_ >= 0) {
    termios raw{};
    if (::tcgetattr(pty->slave_fd_, &raw) == 0) {
      ::cfmakeraw(&raw);
      ::tcsetattr(pty->slave_fd_, TCSANOW, &raw);
    }
  }
  // A UART does not wait for its reader: neither does the player.
  ::fcntl(pty->master_fd_, F_SETFL, ::fcntl(pty->master_fd_, F_GETFL) | O_NONBLOCK);
  pty->on_end_ = std::move(on_end);

  NmeaPtyPlayer* self = pty.get();
  auto player = NmeaPlayer::open(
      pty->io_, file, pacing,
      [self](std::string_view bytes) {
        const int error = core::writeFully(self->master_fd_, bytes.data(), bytes.size());
        if (error == 0 || error == EAGAIN || error == EWOULDBLOCK)
          return;  // written, or lost because nobody read the pty
        spdlog::error("NMEA player: {}: {}", self->device_, std::strerror(error));
        self->player_->stop();
        self->finish();
      },
      [self] { self->finish(); });
  if (!player)
    return player.error();
  pty->player_ = std::move(*player);
  pty->timer_.expires_after(kReaderHeadStart);
  pty->timer_.async_wait([self](const boost::system::error_code& error) {
    if (!error)
      self->player_->start();
  });
  pty->thread_ = std::thread([self] { self->io_.run(); });
  return pty;
}

void NmeaPtyPlayer::finish() {
  timer_.expires_after(kLastFixesTime);
  timer_.async_wait([this](const boost::system::error_code& error) {
    if (!error && on_end_)
      on_end_();
  });
}

NmeaPtyPlayer::~NmeaPtyPlayer() {
  io_.stop();
  if (thread_.joinable())
    thread_.join();
  player_.reset();
  if (slave_fd_ >= 0)
    ::close(slave_fd_);
  if (master_fd_ >= 0)
    ::close(master_fd_);
}

}  // namespace fieldrig::sim
