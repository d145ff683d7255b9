// The daemon's status on a local HTTP port (HttpServer):
//   GET /          the in-cab page (cab_page.html, embedded at build time): map, GPS, speed
//                  gauge, alarms with what to do, last plot, queues, disk
//   GET /events    the status as server-sent events ("event: status"), pushed when it changes,
//                  at most every `event_period`, and at least every `refresh_period`
//   GET /status    the JSON snapshot the daemon provides
//   GET /map       the map's static part (locations, rows, local frame), given at start
//   GET /guide     the alarms' meanings and what to do (alarmGuide())
//   and what StatusServerOptions::more_routes answers (fieldrigd: /thumbnail/N.jpg)
//   GET /healthz   "ok"
// Read-only: nothing a request carries can change the run or reach a file. It runs on its own
// threads (one serving, one taking snapshots while a page listens), so a slow or hostile client
// never delays the GPS/trigger thread; it listens on 127.0.0.1 unless configured otherwise.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fieldrig/core/result.h"
#include "fieldrig/daemon/http_server.h"

namespace fieldrig::daemon {

// One alarm kind as docs/field-guide.md explains it (its table "Alarms: what they mean, what to
// do"; a test holds the two equal). Markdown code spans (`x`) are kept.
struct AlarmGuideEntry {
  std::string_view kind;
  std::string_view means;
  std::string_view what_to_do;
};
const std::vector<AlarmGuideEntry>& alarmGuide();
nlohmann::ordered_json alarmGuideJson();

std::string_view cabPageHtml();  // the embedded page

struct StatusServerOptions {
  std::string map_json = "{}";  // served at /map
  // Fields (JSON pointers) that change by themselves as time passes (clocks, ages): a change of
  // only these is pushed at refresh_period, not at event_period.
  std::vector<std::string> clock_fields;
  std::chrono::milliseconds event_period{100};
  std::chrono::milliseconds refresh_period{1000};
  // More read-only GET routes (the last plot's thumbnails): a reply for the path, or nullopt
  // when it is not theirs. Called on the serving thread.
  std::function<std::optional<HttpReply>(const std::string& path)> more_routes;
};

class StatusServer {
 public:
  using Snapshot = std::function<nlohmann::ordered_json()>;

  // Binds address:port (port 0: any free port) and starts serving; the error names the address.
  static core::Result<std::unique_ptr<StatusServer>> start(const std::string& address,
                                                           std::uint16_t port, Snapshot snapshot,
                                                           StatusServerOptions options = {});
  ~StatusServer();  // stops serving and joins the threads
  std::uint16_t port() const;
  std::uint64_t eventsPublished() const;

  struct Impl;

 private:
  explicit StatusServer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace fieldrig::daemon
