// NMEA from a serial port (the auto-guidance receiver) on Boost.Asio.
// Owned by one thread: construct, start, stop and destroy it, and receive its callbacks, on the
// thread running the io_context (or construct/destroy it while no thread runs the io_context).
//
// Each complete sentence is stamped with its reception time on the steady and system clocks.
// When the device vanishes (USB unplugged, cable pulled) the source reports it and reopens the
// same path with exponential backoff until it is back or stop() is called.
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/serial_port.hpp>
#include <boost/asio/steady_timer.hpp>

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "fieldrig/core/result.h"
#include "fieldrig/core/time.h"
#include "fieldrig/gps/nmea_parser.h"

namespace fieldrig::gps {

struct SerialOptions {
  std::string device;      // e.g. /dev/ttyUSB0
  unsigned baud = 115200;  // 4800, 9600, 19200, 38400, 57600 or 115200; always 8N1
  std::chrono::milliseconds reopen_initial_delay{100};
  std::chrono::milliseconds reopen_max_delay{5000};
};

enum class SerialEvent { kOpened, kLost, kOpenFailed };
std::string_view toString(SerialEvent event);

struct SerialStatus {
  SerialEvent event = SerialEvent::kOpened;
  std::string device;
  std::string message;                    // the system's error text for kLost / kOpenFailed
  std::chrono::milliseconds retry_in{0};  // kLost / kOpenFailed: when the next open is tried
};

// A character device that is not a terminal (/dev/null, /dev/zero) is no receiver's serial
// port, and opening it again would go on for ever: the error names it. A device that is not there
// (a USB adapter not plugged in yet) or cannot be opened now is not refused here: the source
// waits for it and reports each attempt.
core::Result<void> checkSerialDevice(const std::string& device);

class SerialNmeaSource {
 public:
  // Every line the parser completes is passed on, rejected ones included (the consumer decides
  // what a reject means); the stamp is when the bytes that completed the line were read. A line
  // cut short by the loss of the device is passed on as rejected, never joined to later data.
  using SentenceHandler = std::function<void(const Sentence&, const core::ReceptionStamp&)>;
  using StatusHandler = std::function<void(const SerialStatus&)>;

  // Opens nothing yet. An error for a baud rate that is not one of the standard rates from 4800
  // to 115200, an empty device path or non-positive / inverted reopen delays.
  static core::Result<std::unique_ptr<SerialNmeaSource>> create(boost::asio::io_context& io,
                                                                SerialOptions options,
                                                                SentenceHandler on_sentence,
                                                                StatusHandler on_status = {});
  ~SerialNmeaSource();
  SerialNmeaSource(const SerialNmeaSource&) = delete;
  SerialNmeaSource& operator=(const SerialNmeaSource&) = delete;

  // The first open is attempted from the io_context, not inside start(), so no callback runs
  // before start() returns. A failed open is reported (kOpenFailed) and retried.
  void start();
  // Closes the port and cancels the retries; no callback is made after it returns, even when
  // called from inside a callback. start() may be called again.
  void stop();

  bool running() const { return running_; }
  bool isOpen() const { return port_.is_open(); }
  std::uint64_t timesLost() const { return times_lost_; }
  std::uint64_t openFailures() const { return open_failures_; }
  std::uint64_t bytesReceived() const { return bytes_received_; }
  const NmeaStats& stats() const { return parser_.stats(); }

 private:
  SerialNmeaSource(boost::asio::io_context& io, SerialOptions options, SentenceHandler on_sentence,
                   StatusHandler on_status);

  // Repeating log lines (a receiver left unplugged retries for hours) are throttled per event.
  struct LogThrottle {
    std::chrono::steady_clock::time_point last{};
    bool logged = false;
    std::uint64_t suppressed = 0;
  };

  void tryOpen();
  void configurePort(boost::system::error_code& error);
  void scheduleReopen(SerialEvent event, const std::string& reason);
  void readSome();
  void handleRead(const boost::system::error_code& error, std::size_t bytes);
  void handleLoss(const boost::system::error_code& error);
  void closePort();
  void report(const SerialStatus& status);
  bool shouldLog(SerialEvent event, std::uint64_t& suppressed);

  boost::asio::io_context& io_;
  SerialOptions options_;
  SentenceHandler on_sentence_;
  StatusHandler on_status_;
  boost::asio::serial_port port_;
  boost::asio::steady_timer reopen_timer_;
  std::chrono::milliseconds next_delay_;
  std::array<char, 4096> buffer_{};
  core::ReceptionStamp chunk_received_{};  // when the chunk being parsed arrived
  NmeaParser parser_;
  bool running_ = false;
  // The backoff is reset by the first data after an open, not by the open itself: a device that
  // opens and fails at once (a dying USB adapter) must not be retried at the shortest delay
  // forever.
  bool data_since_open_ = false;
  std::uint64_t times_lost_ = 0;
  std::uint64_t open_failures_ = 0;
  std::uint64_t bytes_received_ = 0;
  // Bumped whenever the port is closed or the source stopped: a completion handler issued in an
  // earlier epoch (an aborted read, a timer that fired just before stop()) does nothing.
  std::uint64_t epoch_ = 0;
  std::array<LogThrottle, 3> log_throttle_{};  // indexed by SerialEvent
  // Handlers hold a weak reference, so those still queued in the io_context when the source is
  // destroyed do nothing instead of touching freed memory.
  std::shared_ptr<char> alive_ = std::make_shared<char>();
};

}  // namespace fieldrig::gps
