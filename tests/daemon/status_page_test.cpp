// The status port's page and event stream in this process (StatusServer on 127.0.0.1, a
// snapshot the test changes): the embedded page is served and loads nothing from elsewhere, the
// alarm texts are those of docs/field-guide.md, /events pushes a change at once and a
// clock-only change no faster than the refresh period, and nothing but GET/HEAD is answered.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "fieldrig/daemon/status_server.h"
#include "support/http_client.h"

namespace fieldrig::daemon {
namespace {

using testing_support::HttpClient;
using testing_support::httpRequestText;
using namespace std::chrono_literals;
using Json = nlohmann::ordered_json;

std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

struct GuideRow {
  std::string kind, means, what_to_do;
  bool operator==(const GuideRow&) const = default;
};

// The rows of the field guide's table "| alarm | means | do |".
std::vector<GuideRow> fieldGuideAlarms() {
  std::istringstream doc(
      readFile(std::filesystem::path(FIELDRIG_SOURCE_DIR) / "docs" / "field-guide.md"));
  std::vector<GuideRow> rows;
  bool in_table = false;
  const std::regex row(R"(^\| `([a-z_]+)` \| (.*) \| (.*) \|$)");
  for (std::string line; std::getline(doc, line);) {
    if (line.rfind("| alarm | means | do |", 0) == 0) {
      in_table = true;
      continue;
    }
    if (!in_table || line.rfind("| ---", 0) == 0)
      continue;
    std::smatch match;
    if (!std::regex_match(line, match, row))
      break;
    rows.push_back({match[1], match[2], match[3]});
  }
  return rows;
}

TEST(StatusPage, AlarmGuideIsTheFieldGuidesTable) {
  const std::vector<GuideRow> doc = fieldGuideAlarms();
  ASSERT_GE(doc.size(), 7U) << "the table was not found in docs/field-guide.md";
  std::vector<GuideRow> code;
  for (const AlarmGuideEntry& entry : alarmGuide())
    code.push_back(
        {std::string(entry.kind), std::string(entry.means), std::string(entry.what_to_do)});
  EXPECT_EQ(code.size(), doc.size());
  for (std::size_t i = 0; i < std::min(code.size(), doc.size()); ++i) {
    EXPECT_EQ(code[i].kind, doc[i].kind);
    EXPECT_EQ(code[i].means, doc[i].means) << doc[i].kind;
    EXPECT_EQ(code[i].what_to_do, doc[i].what_to_do) << doc[i].kind;
  }
}

// A server on any free port whose snapshot is {"value": value, "time": clock}.
struct Server {
  std::atomic<int> value{0};
  std::atomic<int> clock{0};
  std::unique_ptr<StatusServer> server;

  Server() {
    StatusServerOptions options;
    options.map_json = R"({"locations":[]})";
    options.clock_fields = {"/time"};
    options.event_period = 50ms;
    options.refresh_period = 1000ms;
    auto started = StatusServer::start(
        "127.0.0.1", 0,
        [this] {
          return Json{{"value", value.load()}, {"time", clock.load()}};
        },
        options);
    if (!started)
      throw std::runtime_error(started.error().message);
    server = std::move(*started);
  }
  int port() const { return server->port(); }
};

testing_support::HttpClientReply request(int port, std::string_view method,
                                         std::string_view target) {
  HttpClient client(port);
  client.send(httpRequestText(method, target, "", true));
  return client.readReply();
}

TEST(StatusPage, ServesTheEmbeddedPageTheMapTheGuideAndNothingWritable) {
  Server server;
  const auto page = request(server.port(), "GET", "/");
  EXPECT_EQ(page.status, 200);
  EXPECT_EQ(page.body, std::string(cabPageHtml()));
  EXPECT_NE(page.body.find("<title>fieldrig"), std::string::npos);
  EXPECT_NE(page.body.find("new EventSource(\"/events\")"), std::string::npos);
  // Nothing from the internet: no scripts, styles, images or fonts from another host.
  for (const char* outside : {"src=\"http", "href=\"http", "url(http", "@import", "//cdn"})
    EXPECT_EQ(page.body.find(outside), std::string::npos) << outside;
  EXPECT_EQ(request(server.port(), "GET", "/map").body, "{\"locations\":[]}\n");
  const Json guide = Json::parse(request(server.port(), "GET", "/guide").body);
  EXPECT_EQ(guide.size(), alarmGuide().size());
  EXPECT_EQ(guide.at("gps_lost").at("do"), std::string(alarmGuide().front().what_to_do));
  EXPECT_EQ(Json::parse(request(server.port(), "GET", "/status?x=1").body).at("value"), 0);
  for (const char* method : {"POST", "PUT", "DELETE"}) {
    EXPECT_EQ(request(server.port(), method, "/status").status, 405) << method;
    EXPECT_EQ(request(server.port(), method, "/events").status, 405) << method;
  }
  EXPECT_EQ(request(server.port(), "GET", "/nothing").status, 404);
}

TEST(StatusPage, EventsPushAChangeAtOnceAndClockOnlyChangesAtTheRefreshPeriod) {
  Server server;
  HttpClient client(server.port());
  ASSERT_TRUE(client.send(httpRequestText("GET", "/events")));
  const std::string head = client.takeUntil("\r\n\r\n", 10s);
  ASSERT_NE(head.find("200 OK"), std::string::npos) << head;
  EXPECT_NE(head.find("Content-Type: text/event-stream"), std::string::npos) << head;
  EXPECT_EQ(head.find("Content-Length"), std::string::npos) << head;
  EXPECT_EQ(client.takeUntil("\n\n", 10s), "retry: 1000\n\n");
  const std::string first = client.takeUntil("\n\n", 10s);
  EXPECT_EQ(first, "event: status\ndata: {\"value\":0,\"time\":0}\n\n");

  // Only the clock moves, every few milliseconds, for 2.5 s: pushed about once a second (at
  // the 50 ms event period it would be some 50 times).
  int clock_events = 0;
  const auto until = std::chrono::steady_clock::now() + 2500ms;
  std::thread ticking([&] {
    while (std::chrono::steady_clock::now() < until) {
      ++server.clock;
      std::this_thread::sleep_for(5ms);
    }
  });
  while (std::chrono::steady_clock::now() < until) {
    const std::string event = client.takeUntil("\n\n", 200ms);
    if (!event.empty()) {
      EXPECT_NE(event.find("\"value\":0"), std::string::npos) << event;
      ++clock_events;
    }
  }
  ticking.join();
  EXPECT_GE(clock_events, 1);
  EXPECT_LE(clock_events, 6);

  // A real change goes out without waiting for the refresh period.
  server.value = 7;
  std::string event;
  for (int i = 0; i < 5 && event.find("\"value\":7") == std::string::npos; ++i)
    event = client.takeUntil("\n\n", 10s);
  EXPECT_NE(event.find("\"value\":7"), std::string::npos) << event;
  EXPECT_GE(server.server->eventsPublished(), 2U);

  // A second page gets the latest state at once.
  HttpClient second(server.port());
  ASSERT_TRUE(second.send(httpRequestText("GET", "/events")));
  ASSERT_FALSE(second.takeUntil("retry: 1000\n\n", 10s).empty());
  EXPECT_NE(second.takeUntil("\n\n", 10s).find("\"value\":7"), std::string::npos);
}

TEST(StatusPage, AStreamThatIsNeverReadDoesNotHoldTheServerUp) {
  Server server;
  std::vector<HttpClient> silent;
  for (int i = 0; i < 5; ++i) {
    silent.emplace_back(server.port());
    ASSERT_TRUE(silent.back().send(httpRequestText("GET", "/events")));
  }
  // Events pile up unread in those sockets; /status and /healthz are still answered.
  for (int i = 0; i < 20; ++i) {
    server.value = i;
    std::this_thread::sleep_for(20ms);
  }
  EXPECT_EQ(request(server.port(), "GET", "/healthz").body, "ok\n");
  EXPECT_EQ(Json::parse(request(server.port(), "GET", "/status").body).at("value"), 19);
}

}  // namespace
}  // namespace fieldrig::daemon
