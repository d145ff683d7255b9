// The NMEA player: a capture played back at the pace of its own GPS times, as the receiver sent
// it, into whatever reads NMEA bytes. The pacing is pure (NmeaPacer); the transports are thin
// shells around it: NmeaPlayer hands the bytes to a consumer's feed() in the same process
// (`fieldrig map record` on a file or FIFO), NmeaPtyPlayer writes them into a pseudo-terminal
// read as a serial port (the daemon's real-time replay through gps::SerialNmeaSource).
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/steady_timer.hpp>

#include <array>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

#include "fieldrig/core/result.h"
#include "fieldrig/core/time.h"
#include "fieldrig/gps/fix_assembler.h"

namespace fieldrig::sim {

struct NmeaPacing {
  bool realtime = true;  // false: as fast as the consumer takes the bytes
  // A longer pause in the capture (the receiver off for lunch) is shortened to this, so that a
  // replay never sits idle; none: every pause is played as it was.
  std::optional<core::Nanoseconds> max_gap;
};

// The wait before each line of a capture. Pure, thread-compatible.
//
// A line's time is its RMC/GGA epoch (date from the RMCs, midnight crossed by GGA-only captures
// too). The first timed line, a line of the same time as the previous one and a line whose time
// goes back (another capture appended) wait for nothing; a later one waits for the GPS time since
// the previous timed line, at most max_gap. Other lines (other sentences, comments, noise) wait
// for nothing.
class NmeaPacer {
 public:
  explicit NmeaPacer(std::optional<core::Nanoseconds> max_gap = std::nullopt) : max_gap_(max_gap) {}

  // `line` without its line end (a trailing CR is ignored).
  core::Nanoseconds waitBefore(std::string_view line);

 private:
  std::optional<core::Nanoseconds> max_gap_;
  gps::FixAssembler assembler_;
  std::optional<core::UtcTime> last_time_;
};

// Plays a capture on an io_context: a regular file line by line when each is due (CR LF ends
// every line, as receivers send them), or a chunk per turn of the loop when not in real time; a
// FIFO as its writer delivers it. Owned by the io thread: create, start, stop and destroy it, and
// receive its callbacks, on the thread running the io_context (or while no thread runs it).
class NmeaPlayer {
 public:
  using BytesHandler = std::function<void(std::string_view bytes)>;

  // Opens `path`: a regular file, or a FIFO (which blocks until a writer opens it). `on_end` is
  // called once, after the last bytes, at the end of the file or when the FIFO's writer closes.
  static core::Result<std::unique_ptr<NmeaPlayer>> open(boost::asio::io_context& io,
                                                        const std::filesystem::path& path,
                                                        NmeaPacing pacing, BytesHandler on_bytes,
                                                        std::function<void()> on_end);
  ~NmeaPlayer();
  NmeaPlayer(const NmeaPlayer&) = delete;
  NmeaPlayer& operator=(const NmeaPlayer&) = delete;

  // The first bytes are handed over from the io_context, not inside start().
  void start();
  // No callback is made after it returns. Final.
  void stop();

 private:
  NmeaPlayer(boost::asio::io_context& io, NmeaPacing pacing, BytesHandler on_bytes,
             std::function<void()> on_end);
  void playFile();
  void readStream();
  void end();

  boost::asio::io_context& io_;
  NmeaPacing pacing_;
  BytesHandler on_bytes_;
  std::function<void()> on_end_;
  std::ifstream file_;                                           // a regular file, or
  std::optional<boost::asio::posix::stream_descriptor> stream_;  // a FIFO
  boost::asio::steady_timer timer_;
  NmeaPacer pacer_;
  std::optional<std::string> pending_;  // the next line, read but not yet due
  std::chrono::steady_clock::time_point deadline_{};
  std::array<char, 65536> buffer_{};
  bool stopped_ = false;
  std::shared_ptr<char> alive_ = std::make_shared<char>();  // expires with the player
};

// Plays a capture file into a pseudo-terminal of its own, read as a serial port on devicePath():
// the field's serial path without a receiver. A thread of its own plays (an NmeaPlayer on its own
// io_context), so that the reader's thread never waits on it, as on a receiver; a reader that
// stops reading loses bytes, as on a UART, rather than blocking the player. The slave side is
// held open so that the pty survives the reader's reopenings. Construct and destroy it on one
// thread; `on_end` is called from the player's thread once the whole file has been written and
// the last fixes have had time to be read.
class NmeaPtyPlayer {
 public:
  static core::Result<std::unique_ptr<NmeaPtyPlayer>> start(const std::filesystem::path& file,
                                                            NmeaPacing pacing,
                                                            std::function<void()> on_end);
  ~NmeaPtyPlayer();  // stops playing, closes the pty
  NmeaPtyPlayer(const NmeaPtyPlayer&) = delete;
  NmeaPtyPlayer& operator=(const NmeaPtyPlayer&) = delete;

  const std::string& devicePath() const { return device_; }

 private:
  NmeaPtyPlayer() = default;
  void finish();  // on the player's thread: the file is over, or the pty failed

  int master_fd_ = -1;
  int slave_fd_ = -1;
  std::string device_;
  boost::asio::io_context io_;
  std::unique_ptr<NmeaPlayer> player_;    // runs on io_, in thread_
  boost::asio::steady_timer timer_{io_};  // the reader's head start, then the last fixes' time
  std::function<void()> on_end_;
  std::thread thread_;
};

}  // namespace fieldrig::sim
