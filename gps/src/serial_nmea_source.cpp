#include "fieldrig/gps/serial_nmea_source.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <boost/asio/post.hpp>

#include <algorithm>
#include <string_view>
#include <utility>

namespace fieldrig::gps {
namespace {

constexpr std::array<unsigned, 6> kStandardBaudRates{4800, 9600, 19200, 38400, 57600, 115200};

// A receiver left unplugged fails an open every reopen_max_delay for as long as the run lasts;
// one line per event kind in this interval says the same thing with a count.
constexpr std::chrono::seconds kRepeatLogInterval{10};

std::string suppressedNote(std::uint64_t suppressed) {
  return suppressed == 0 ? std::string{}
                         : fmt::format(" ({} similar lines suppressed)", suppressed);
}

}  // namespace

std::string_view toString(SerialEvent event) {
  switch (event) {
    case SerialEvent::kOpened:
      return "opened";
    case SerialEvent::kLost:
      return "lost";
    case SerialEvent::kOpenFailed:
      return "open_failed";
  }
  return "unknown";
}

core::Result<std::unique_ptr<SerialNmeaSource>> SerialNmeaSource::create(
    boost::asio::io_context& io, SerialOptions options, SentenceHandler on_sentence,
    StatusHandler on_status) {
  if (std::find(kStandardBaudRates.begin(), kStandardBaudRates.end(), options.baud) ==
      kStandardBaudRates.end()) {
    return core::Error{
        fmt::format("serial port {}: unsupported baud rate {} (use 4800, 9600, 19200, 38400, "
                    "57600 or 115200)",
                    options.device, options.baud)};
  }
  if (options.device.empty())
    return core::Error{"serial port: empty device path"};
  if (options.reopen_initial_delay.count() <= 0 ||
      options.reopen_max_delay < options.reopen_initial_delay) {
    return core::Error{fmt::format(
        "serial port {}: reopen delays must satisfy 0 < initial ({} ms) <= max ({} ms)",
        options.device, options.reopen_initial_delay.count(), options.reopen_max_delay.count())};
  }
  return std::unique_ptr<SerialNmeaSource>(
      new SerialNmeaSource(io, std::move(options), std::move(on_sentence), std::move(on_status)));
}

SerialNmeaSource::SerialNmeaSource(boost::asio::io_context& io, SerialOptions options,
                                   SentenceHandler on_sentence, StatusHandler on_status)
    : io_(io),
      options_(std::move(options)),
      on_sentence_(std::move(on_sentence)),
      on_status_(std::move(on_status)),
      port_(io),
      reopen_timer_(io),
      next_delay_(options_.reopen_initial_delay),
      parser_([this](const Sentence& sentence) {
        // stop() from inside a callback ends the callbacks even within the chunk being parsed.
        if (running_ && on_sentence_)
          on_sentence_(sentence, chunk_received_);
      }) {}

SerialNmeaSource::~SerialNmeaSource() {
  stop();
}

void SerialNmeaSource::start() {
  if (running_)
    return;
  running_ = true;
  next_delay_ = options_.reopen_initial_delay;
  const std::uint64_t epoch = epoch_;
  boost::asio::post(io_, [this, alive = std::weak_ptr<char>(alive_), epoch] {
    if (alive.expired() || epoch != epoch_ || !running_)
      return;
    tryOpen();
  });
}

void SerialNmeaSource::stop() {
  running_ = false;
  ++epoch_;
  reopen_timer_.cancel();
  boost::system::error_code ignored;
  port_.close(ignored);
}

core::Result<void> checkSerialDevice(const std::string& device) {
  const int fd = ::open(device.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0)
    return {};
  const bool terminal = ::isatty(fd) == 1;
  ::close(fd);
  if (!terminal)
    return core::Error{device + ": a character device but not a serial port (not a terminal)"};
  return {};
}

void SerialNmeaSource::closePort() {
  boost::system::error_code ignored;
  port_.close(ignored);
  ++epoch_;
}

void SerialNmeaSource::configurePort(boost::system::error_code& error) {
  using boost::asio::serial_port_base;
  port_.set_option(serial_port_base::baud_rate(options_.baud), error);
  if (!error)
    port_.set_option(serial_port_base::character_size(8), error);
  if (!error)
    port_.set_option(serial_port_base::parity(serial_port_base::parity::none), error);
  if (!error)
    port_.set_option(serial_port_base::stop_bits(serial_port_base::stop_bits::one), error);
  if (!error) {
    port_.set_option(serial_port_base::flow_control(serial_port_base::flow_control::none), error);
  }
}

void SerialNmeaSource::tryOpen() {
  boost::system::error_code error;
  port_.open(options_.device, error);
  if (!error)
    configurePort(error);
  if (error) {
    closePort();
    ++open_failures_;
    scheduleReopen(SerialEvent::kOpenFailed, error.message());
    return;
  }
  data_since_open_ = false;
  const std::uint64_t epoch = epoch_;
  // Normally empty: a line left by stop() in the middle of it is reported now as the truncated
  // line it is, so that it cannot be completed by the first bytes of the new connection.
  parser_.flush();
  if (epoch != epoch_ || !running_)
    return;

  std::uint64_t suppressed = 0;
  if (shouldLog(SerialEvent::kOpened, suppressed)) {
    spdlog::info("serial port {}: opened at {} baud, 8N1{}", options_.device, options_.baud,
                 suppressedNote(suppressed));
  }
  report({SerialEvent::kOpened, options_.device, {}, std::chrono::milliseconds{0}});
  if (epoch != epoch_ || !running_)
    return;
  readSome();
}

void SerialNmeaSource::scheduleReopen(SerialEvent event, const std::string& reason) {
  const std::chrono::milliseconds delay = next_delay_;
  next_delay_ = std::min(next_delay_ * 2, options_.reopen_max_delay);

  std::uint64_t suppressed = 0;
  if (shouldLog(event, suppressed)) {
    spdlog::warn("serial port {}: {} ({}); retrying in {} ms{}", options_.device,
                 event == SerialEvent::kLost ? "lost" : "cannot open", reason, delay.count(),
                 suppressedNote(suppressed));
  }
  // Armed before reporting, so that a stop() from the status callback cancels it.
  const std::uint64_t epoch = epoch_;
  reopen_timer_.expires_after(delay);
  reopen_timer_.async_wait(
      [this, alive = std::weak_ptr<char>(alive_), epoch](const boost::system::error_code& error) {
        if (alive.expired() || error || epoch != epoch_ || !running_)
          return;
        tryOpen();
      });
  report({event, options_.device, reason, delay});
}

void SerialNmeaSource::readSome() {
  const std::uint64_t epoch = epoch_;
  port_.async_read_some(boost::asio::buffer(buffer_),
                        [this, alive = std::weak_ptr<char>(alive_), epoch](
                            const boost::system::error_code& error, std::size_t bytes) {
                          // Aborted reads of a port closed on purpose (loss handled, stop) belong
                          // to an old epoch.
                          if (alive.expired() || epoch != epoch_ || !running_)
                            return;
                          handleRead(error, bytes);
                        });
}

void SerialNmeaSource::handleRead(const boost::system::error_code& error, std::size_t bytes) {
  // Any error on an open port means the device is gone or unusable (EOF, EIO when a USB adapter
  // or a pty master disappears, operation_aborted not caused by us): reopening is the only cure.
  if (error) {
    handleLoss(error);
    return;
  }
  chunk_received_ = core::ReceptionStamp::now();
  bytes_received_ += bytes;
  if (bytes > 0 && !data_since_open_) {
    data_since_open_ = true;
    next_delay_ = options_.reopen_initial_delay;
  }
  const std::uint64_t epoch = epoch_;
  parser_.feed(std::string_view(buffer_.data(), bytes));
  if (epoch != epoch_ || !running_)
    return;
  readSome();
}

void SerialNmeaSource::handleLoss(const boost::system::error_code& error) {
  closePort();
  ++times_lost_;
  const std::uint64_t epoch = epoch_;
  // The partial line the device was sending when it vanished is reported as rejected now: the
  // first bytes after a reopen start mid-stream and must not complete it.
  parser_.flush();
  if (epoch != epoch_ || !running_)
    return;
  scheduleReopen(SerialEvent::kLost, error.message());
}

void SerialNmeaSource::report(const SerialStatus& status) {
  if (on_status_)
    on_status_(status);
}

bool SerialNmeaSource::shouldLog(SerialEvent event, std::uint64_t& suppressed) {
  LogThrottle& throttle = log_throttle_[static_cast<std::size_t>(event)];
  const auto now = std::chrono::steady_clock::now();
  if (throttle.logged && now - throttle.last < kRepeatLogInterval) {
    ++throttle.suppressed;
    return false;
  }
  suppressed = std::exchange(throttle.suppressed, 0);
  throttle.logged = true;
  throttle.last = now;
  return true;
}

}  // namespace fieldrig::gps
