// The daemon's status on a local HTTP port (HttpServer): GET /status answers the JSON snapshot
// the daemon provides; GET /healthz answers "ok". Read-only: nothing a request carries can change
// the run or reach a file. It runs on its own thread, so a slow or hostile client never delays
// the GPS/trigger thread; it listens on 127.0.0.1 unless configured otherwise.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "fieldrig/core/result.h"

namespace fieldrig::daemon {

class StatusServer {
 public:
  using Snapshot = std::function<nlohmann::ordered_json()>;

  // Binds address:port (port 0: any free port) and starts serving; the error names the address.
  static core::Result<std::unique_ptr<StatusServer>> start(const std::string& address,
                                                           std::uint16_t port, Snapshot snapshot);
  ~StatusServer();  // stops serving and joins the thread
  std::uint16_t port() const;

  struct Impl;

 private:
  explicit StatusServer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace fieldrig::daemon
