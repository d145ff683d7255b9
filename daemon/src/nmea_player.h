// Plays an NMEA capture into a pseudo-terminal of its own at the pace of the sentences' times,
// so that a real-time replay reads it through the very serial path of the field
// (gps::SerialNmeaSource on the pty's device). One thread writes; `on_end` is called from it
// once the whole file has been written.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "fieldrig/core/result.h"

namespace fieldrig::daemon {

class NmeaPlayer {
 public:
  static core::Result<std::unique_ptr<NmeaPlayer>> start(const std::filesystem::path& file,
                                                         std::function<void()> on_end);
  ~NmeaPlayer();  // stops writing, closes the pty
  const std::string& devicePath() const { return device_; }

 private:
  NmeaPlayer() = default;
  void play(std::string content);

  int master_fd_ = -1;
  int slave_fd_ = -1;  // held open so the pty survives the reader's reopenings
  std::string device_;
  std::function<void()> on_end_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace fieldrig::daemon
