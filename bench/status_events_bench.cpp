// The CPU that the in-cab page's live updates cost the daemon: a StatusServer pushing its status
// at 10 Hz (/events) to 1 and 3 pages, with a snapshot shaped and costed like fieldrigd's (the
// status fields, one state per map location, a statvfs of the session's disk and a read of
// /proc/self/statm per snapshot; something changes every time, so every period is pushed). The
// pages are sockets read by a child process, so that only the server side is measured: the
// process's CPU time (all threads) over 10 s of wall time, as % of one core. Maps of 12, 1,000,
// 10,000 and 100,000 locations. Prints a Markdown table.
//   status_events_bench [seconds]
#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "fieldrig/daemon/status_server.h"
#include "process_cpu.h"

namespace {

using Json = nlohmann::ordered_json;
using namespace std::chrono_literals;

// Connects `pages` clients to /events and reads them until killed.
pid_t startPages(int port, int pages) {
  const pid_t pid = ::fork();
  if (pid != 0)
    return pid;
  std::vector<int> fds;
  for (int i = 0; i < pages; ++i) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<std::uint16_t>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0)
      ::_exit(1);
    const std::string request = "GET /events HTTP/1.1\r\nHost: localhost\r\n\r\n";
    if (::write(fd, request.data(), request.size()) < 0)
      ::_exit(1);
    fds.push_back(fd);
  }
  std::vector<char> buffer(1 << 16);
  for (;;) {
    for (int fd : fds) {
      if (::recv(fd, buffer.data(), buffer.size(), MSG_DONTWAIT) == 0)
        ::_exit(0);
    }
    std::this_thread::sleep_for(20ms);
  }
}

struct Figures {
  double cpu_percent = 0;
  double events_per_s = 0;
  std::size_t event_bytes = 0;
};

Figures measure(std::size_t locations, int pages, double seconds) {
  std::atomic<std::uint64_t> calls{0};
  std::string states(locations, '.');
  std::size_t event_bytes = 0;
  auto snapshot = [&]() {
    const std::uint64_t n = calls.fetch_add(1);
    states[n % locations] = "trp"[n % 3];
    Json out;
    out["mode"] = "run";
    out["time"] = "2026-07-14T15:30:07.123Z";
    out["uptime_s"] = static_cast<double>(n) * 0.1;
    out["session"] = "/data/sessions/session_2026-07-14";
    out["gps"] = {{"serial", "opened"}, {"lost", false},       {"fixes", n},
                  {"fix_age_s", 0.05},  {"valid", true},       {"quality", 4},
                  {"satellites", 14},   {"hdop", 0.7},         {"lat", 42.0106 + 1e-7 * n},
                  {"lon", -93.7385},    {"course_deg", 360.0}, {"east_m", 0.0},
                  {"north_m", 0.01 * n}};
    out["speed"] = {{"speed_mps", 1.9}, {"max_speed_mps", 4.0}, {"ratio", 0.475}, {"level", "ok"}};
    Json rows = Json::object();
    for (int r = 1; r <= 20; ++r)
      rows[std::to_string(r)] = {{"locations", 50}, {"fired", 50}, {"late", 0}, {"missed", 0}};
    out["triggers"] = {{"fired", n},
                       {"late", 0},
                       {"missed", 0},
                       {"too_fast", 0},
                       {"refused", 0},
                       {"rows", rows},
                       {"missed_locations", Json::array()}};
    out["locations"] = {{"states", states}, {"current_row", "7"}};
    out["queues"] = {{"in_flight", 1}, {"to_record", 0}};
    out["sets"] = {{"triggered", n}, {"recorded", n}, {"processed", n}};
    out["processing"] = {{"enabled", true},
                         {"last_plot",
                          {{"plot", "R07P12"},
                           {"status", "ok"},
                           {"height_m", 1.53},
                           {"width_m", 0.61},
                           {"vvi", 0.41},
                           {"vai", 0.87},
                           {"partial", false},
                           {"problems", Json::array()}}}};
    struct statvfs disk {};
    ::statvfs("/tmp", &disk);
    out["disk"] = {{"free_bytes", static_cast<double>(disk.f_bavail) * disk.f_frsize}};
    std::ifstream statm("/proc/self/statm");
    std::size_t total = 0, resident = 0;
    statm >> total >> resident;
    out["memory"] = {{"rss_mb", resident}};
    out["alarms"] = Json::array();
    return out;
  };
  event_bytes = snapshot().dump().size();
  calls = 0;
  auto server = fieldrig::daemon::StatusServer::start("127.0.0.1", 0, snapshot);
  if (!server) {
    std::fprintf(stderr, "%s\n", server.error().message.c_str());
    std::exit(1);
  }
  const pid_t child = startPages((*server)->port(), pages);
  std::this_thread::sleep_for(1s);  // connected, first events out
  const std::uint64_t events_before = (*server)->eventsPublished();
  const double cpu_before = fieldrig::bench::processCpuSeconds();
  const auto wall_before = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  const double cpu = fieldrig::bench::processCpuSeconds() - cpu_before;
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_before).count();
  const std::uint64_t events = (*server)->eventsPublished() - events_before;
  ::kill(child, SIGKILL);
  ::waitpid(child, nullptr, 0);
  server->reset();
  return {100.0 * cpu / wall, static_cast<double>(events) / wall, event_bytes};
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 10.0;
  std::printf("| map locations | pages | events/s | bytes/event | daemon CPU (%% of one core) |\n");
  std::printf("| ---: | ---: | ---: | ---: | ---: |\n");
  for (const std::size_t locations : {12UL, 1'000UL, 10'000UL, 100'000UL}) {
    for (const int pages : {1, 3}) {
      const Figures f = measure(locations, pages, seconds);
      std::printf("| %zu | %d | %.1f | %zu | %.2f |\n", locations, pages, f.events_per_s,
                  f.event_bytes, f.cpu_percent);
      std::fflush(stdout);
    }
  }
  return 0;
}
