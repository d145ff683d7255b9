// A file read as a stream that another thread can end at any moment.
//
// An NMEA capture is usually a regular file, but a crew also replays through a FIFO (`<(…)`,
// `/dev/stdin`, a logger's pipe). There a plain std::ifstream waits in read() for as long as
// the writer keeps its end open, and a SIGTERM then changes nothing. Here the file is read
// without blocking and waited for in poll() beside an eventfd: interrupt() makes the stream end
// (as at end of file) at once, whatever the file is. A FIFO that no writer has opened yet is
// waited for, as a blocking open would.
//
// Boost.Asio's stream_descriptor would do the waiting, but the replay reads a std::istream
// synchronously (gps::replayTriggers); a stream buffer of a page keeps that contract.
//
// Thread contract: stream() is read by one thread; interrupt() from any thread, also from a
// signal handler (it is one write() to the eventfd).
#pragma once

#include <atomic>
#include <filesystem>
#include <istream>
#include <memory>
#include <streambuf>
#include <string>
#include <vector>

#include "fieldrig/core/result.h"

namespace fieldrig::core {

class InterruptibleInput {
 public:
  // An error names the path and the reason (missing, a folder, unreadable).
  static Result<std::unique_ptr<InterruptibleInput>> open(const std::filesystem::path& path);
  ~InterruptibleInput();
  InterruptibleInput(const InterruptibleInput&) = delete;
  InterruptibleInput& operator=(const InterruptibleInput&) = delete;

  std::istream& stream() { return stream_; }
  // Ends the stream: a read waiting now returns end of file, and so does every later one.
  void interrupt() noexcept;
  bool interrupted() const { return interrupted_.load(std::memory_order_acquire); }
  // A read error (not an interrupt, not the end): empty when there was none.
  const std::string& readError() const { return read_error_; }

 private:
  class Buffer : public std::streambuf {
   public:
    explicit Buffer(InterruptibleInput& owner) : owner_(owner) {}

   protected:
    int_type underflow() override;

   private:
    InterruptibleInput& owner_;
  };

  InterruptibleInput(int file, int wake, std::filesystem::path path, bool named_fifo);

  int file_ = -1;
  int wake_ = -1;  // eventfd: readable once interrupt() ran
  std::filesystem::path path_;
  bool named_fifo_ = false;
  bool writer_seen_ = false;  // a named FIFO's writer came: reading 0 is now its end
  std::atomic<bool> interrupted_{false};
  std::string read_error_;
  std::vector<char> chunk_;
  Buffer buffer_{*this};
  std::istream stream_{&buffer_};
};

}  // namespace fieldrig::core
