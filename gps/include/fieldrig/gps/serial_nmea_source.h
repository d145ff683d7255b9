// NMEA from a serial port (the auto-guidance receiver) on Boost.Asio.
// Owned by one thread: construct, start and stop it, and receive its callbacks, on the thread
// running the io_context.
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
#include <string>

#include "fieldrig/core/time.h"
#include "fieldrig/gps/nmea_parser.h"

namespace fieldrig::gps {

struct SerialOptions {
  std::string device;               // e.g. /dev/ttyUSB0
  unsigned baud = 115200;           // 4800 … 115200
  std::chrono::milliseconds reopen_initial_delay{100};
  std::chrono::milliseconds reopen_max_delay{5000};
};

enum class SerialEvent { kOpened, kLost, kOpenFailed };

struct SerialStatus {
  SerialEvent event = SerialEvent::kOpened;
  std::string device;
  std::string message;              // the system's error text for kLost / kOpenFailed
  std::chrono::milliseconds retry_in{0};
};

class SerialNmeaSource {
 public:
  using SentenceHandler = std::function<void(const Sentence&, const core::ReceptionStamp&)>;
  using StatusHandler = std::function<void(const SerialStatus&)>;

  // Throws std::invalid_argument for a baud rate outside 4800…115200 (a start-up error).
  SerialNmeaSource(boost::asio::io_context& io, SerialOptions options, SentenceHandler on_sentence,
                   StatusHandler on_status = {});
  ~SerialNmeaSource();
  SerialNmeaSource(const SerialNmeaSource&) = delete;
  SerialNmeaSource& operator=(const SerialNmeaSource&) = delete;

  void start();
  void stop();

  bool isOpen() const { return port_.is_open(); }
  std::uint64_t timesLost() const { return times_lost_; }
  const NmeaStats& stats() const { return parser_.stats(); }

 private:
  void tryOpen();
  void scheduleReopen(const std::string& reason);
  void readSome();
  void handleRead(const boost::system::error_code& error, std::size_t bytes);

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
  std::uint64_t times_lost_ = 0;
};

}  // namespace fieldrig::gps
