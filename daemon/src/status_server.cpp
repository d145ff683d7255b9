#include "fieldrig/daemon/status_server.h"

#include <atomic>
#include <boost/asio/ip/address.hpp>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "fieldrig/daemon/http_server.h"

namespace fieldrig::daemon {
namespace {

namespace http = boost::beast::http;
using Json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

// How long a stopping server gives its open pages to take the last state.
constexpr std::chrono::milliseconds kLastEventGrace{300};

// One request per connection, small and quick: a request larger than 8 KiB or slower than 5 s
// is dropped. An event stream stays open; a client that does not take an event within 5 s is
// dropped (its page reconnects).
HttpServerOptions statusServerOptions() {
  HttpServerOptions options;
  options.name = "fieldrigd";
  options.request_timeout = std::chrono::seconds{5};
  options.write_timeout = std::chrono::seconds{5};
  options.body_limit = 8 << 10;
  options.header_limit = 8 << 10;
  options.keep_alive = false;
  options.threads = 1;
  return options;
}

struct Routes {
  StatusServer::Snapshot snapshot;
  std::string map_json;
  std::string guide_json;
  std::shared_ptr<EventFeed> feed;
  std::function<std::optional<HttpReply>(const std::string& path)> more_routes;
};

HttpReply answer(const Routes& routes, const HttpRequest& request) {
  HttpReply reply;
  // The path without a query: a page may add "?t=…" to defeat a cache.
  const std::string path = request.target.substr(0, request.target.find('?'));
  if (request.method != http::verb::get && request.method != http::verb::head) {
    reply = {
        http::status::method_not_allowed, "text/plain", "read-only\n", {{"Allow", "GET, HEAD"}}};
  } else if (path == "/" || path == "/index.html") {
    reply = {http::status::ok, "text/html; charset=utf-8", std::string(cabPageHtml()), {}};
  } else if (path == "/status" || path == "/status.json") {
    reply = {http::status::ok, "application/json", routes.snapshot().dump() + "\n", {}};
  } else if (path == "/map") {
    reply = {http::status::ok, "application/json", routes.map_json, {}};
  } else if (path == "/guide") {
    reply = {http::status::ok, "application/json", routes.guide_json, {}};
  } else if (path == "/events" && request.method == http::verb::get) {
    // The page reconnects a second after the daemon went away (EventSource's retry).
    reply.body = "retry: 1000\n\n";
    reply.events = routes.feed;
  } else if (path == "/healthz") {
    reply = {http::status::ok, "text/plain", "ok\n", {}};
  } else if (auto more = routes.more_routes ? routes.more_routes(path) : std::nullopt) {
    reply = std::move(*more);
  } else {
    reply = {http::status::not_found,
             "text/plain",
             "fieldrigd serves / (the in-cab page), /events, /status (JSON), /map, /guide and "
             "/healthz\n",
             {}};
  }
  if (request.method == http::verb::head)
    reply.body.clear();
  return reply;
}

}  // namespace

const std::vector<AlarmGuideEntry>& alarmGuide() {
  static const std::vector<AlarmGuideEntry> guide = {
      {"gps_lost", "no valid fix for over 1 s (cable, receiver, lost RTK): no triggers",
       "check the receiver and its cable; the plots passed meanwhile are listed as `missed`"},
      {"gps_recovered", "valid fixes again", "nothing; triggering resumes by itself"},
      {"serial_lost", "the serial device vanished (USB pulled)",
       "re-plug; the daemon reopens it by itself"},
      {"missed", "a location was passed without a trigger (GPS gap, invalid or stale fixes)",
       "drive that plot again (it re-arms 3 m away) or note it"},
      {"too_fast",
       "two locations came closer in time than the cameras' fastest rate: a trigger was delayed",
       "slow down; `speed.level` turns `warn` at 80 % of the limit"},
      {"position_jump",
       "the receiver's position leapt further than the tractor can move (a glitch of its "
       "solution): plots between the two positions are neither triggered nor listed as missed",
       "check the plots around the jump in the results; watch the RTK status"},
      {"time_jump", "GPS time went back by more than 2 s: the track started over",
       "check the receiver's date and time; triggering resumes by itself"},
      {"recording_stopped",
       "the disk is full or failing: nothing more is recorded; what was recorded is whole",
       "swap or clear the disk, then restart the daemon"},
      {"results_not_written", "a results file could not be written",
       "check the disk; `fieldrig process` rebuilds the results from the recording"},
  };
  return guide;
}

Json alarmGuideJson() {
  Json guide = Json::object();
  for (const AlarmGuideEntry& entry : alarmGuide())
    guide[std::string(entry.kind)] = {{"means", entry.means}, {"do", entry.what_to_do}};
  return guide;
}

struct StatusServer::Impl {
  std::unique_ptr<HttpServer> server;
  Snapshot snapshot;
  std::shared_ptr<EventFeed> feed;
  std::thread thread;
  // The publisher: takes a snapshot every event_period while a page listens.
  std::thread publisher;
  std::mutex mutex;
  std::condition_variable wake;
  bool stopping = false;  // guarded by mutex
  std::atomic<std::uint64_t> published{0};

  void publish(const StatusServerOptions& options);
};

void StatusServer::Impl::publish(const StatusServerOptions& options) {
  std::string last_without_clocks;
  Clock::time_point last_sent{};
  std::unique_lock lock(mutex);
  while (!wake.wait_for(lock, options.event_period, [this] { return stopping; })) {
    if (feed->subscribers() == 0) {
      last_without_clocks.clear();  // a new page gets the state at once
      continue;
    }
    lock.unlock();
    const Json state = snapshot();
    Json without_clocks = state;
    for (const std::string& field : options.clock_fields) {
      const Json::json_pointer pointer(field);
      if (without_clocks.contains(pointer)) {
        without_clocks.at(pointer.parent_pointer()).erase(pointer.back());
      }
    }
    std::string compared = without_clocks.dump();
    const Clock::time_point now = Clock::now();
    if (compared != last_without_clocks || now - last_sent >= options.refresh_period) {
      feed->publish("event: status\ndata: " + state.dump() + "\n\n");
      published.fetch_add(1, std::memory_order_relaxed);
      last_without_clocks = std::move(compared);
      last_sent = now;
    }
    lock.lock();
  }
}

core::Result<std::unique_ptr<StatusServer>> StatusServer::start(const std::string& address,
                                                                std::uint16_t port,
                                                                Snapshot snapshot,
                                                                StatusServerOptions options) {
  boost::system::error_code error;
  const auto ip = boost::asio::ip::make_address(address, error);
  if (error)
    return core::Error{"status.address '" + address + "': not an IP address"};
  auto server = HttpServer::listen(ip, port, statusServerOptions());
  if (!server)
    return core::Error{"status server: " + server.error().message};
  auto impl = std::make_unique<Impl>();
  impl->server = std::move(*server);
  auto routes = std::make_shared<Routes>();
  routes->snapshot = std::move(snapshot);
  routes->map_json = options.map_json + "\n";
  routes->guide_json = alarmGuideJson().dump() + "\n";
  routes->feed = std::make_shared<EventFeed>();
  routes->more_routes = options.more_routes;
  impl->snapshot = routes->snapshot;
  impl->feed = routes->feed;
  impl->thread = std::thread([server = impl->server.get(), routes] {
    server->run([&routes](const HttpRequest& request) { return answer(*routes, request); });
  });
  impl->publisher =
      std::thread([impl = impl.get(), options = std::move(options)] { impl->publish(options); });
  return std::unique_ptr<StatusServer>(new StatusServer(std::move(impl)));
}

StatusServer::StatusServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

StatusServer::~StatusServer() {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->stopping = true;
  }
  impl_->wake.notify_all();
  if (impl_->publisher.joinable())
    impl_->publisher.join();
  // The run's last state reaches the open pages before the port closes (the last plot's
  // colour, which may have come less than an event period before the end).
  if (impl_->feed->subscribers() > 0) {
    impl_->feed->publish("event: status\ndata: " + impl_->snapshot().dump() + "\n\n");
    std::this_thread::sleep_for(kLastEventGrace);
  }
  impl_->server->stop();
  if (impl_->thread.joinable())
    impl_->thread.join();
}

std::uint16_t StatusServer::port() const {
  return impl_->server->port();
}

std::uint64_t StatusServer::eventsPublished() const {
  return impl_->published.load(std::memory_order_relaxed);
}

}  // namespace fieldrig::daemon
