// `fieldrig view SESSION [--map MAP.csv] [--results DIR] [--port P] [--bind A] [--stem-port P]`:
// the in-cab page (daemon/page/cab_page.html, served by daemon::StatusServer as fieldrigd does)
// on a recorded session: the coverage map, the per-plot results and, for each plot, a link to
// the stem tool (`fieldrig stem-ui SESSION --port STEM_PORT`). The status is built once from the
// session ("mode": "session"); it is read-only and listens on 127.0.0.1 unless told otherwise.
// The first stdout line names the URL (tests and scripts read the port from it, useful with
// --port 0); it serves until SIGINT or SIGTERM.
// Exit codes: 2 a session, map or results that cannot be used, or a bad --bind; 3 cannot listen.
#include <csignal>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "commands/command_helpers.h"
#include "fieldrig/daemon/session_view.h"
#include "fieldrig/daemon/status_server.h"

namespace fieldrig::tools {
namespace {

struct ViewArgs {
  std::string session;
  std::string map;
  std::string results;
  int port = 8770;
  std::string bind = "127.0.0.1";
  int stem_port = 8765;  // stem-ui's default port
};

int runView(const ViewArgs& args) {
  const char* who = "fieldrig view: ";
  daemon::SessionViewOptions options;
  options.session = args.session;
  if (!args.map.empty())
    options.map = args.map;
  if (!args.results.empty())
    options.results = args.results;
  // The stem tool runs on this machine, beside the page.
  options.stem_url = "http://127.0.0.1:" + std::to_string(args.stem_port) + "/";
  auto view = daemon::buildSessionView(options);
  if (!view)
    return fail(who, view.error().message);
  for (const std::string& warning : view->warnings)
    std::cerr << who << "warning: " << warning << '\n';

  // SIGINT and SIGTERM are waited for below, on this thread: blocked before the server's threads
  // start, so that none of them takes one.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  daemon::StatusServerOptions server_options;
  server_options.map_json = view->map_json;
  server_options.more_routes = [plots = view->plots_json + "\n"](
                                   const std::string& path) -> std::optional<daemon::HttpReply> {
    if (path != "/plots")
      return std::nullopt;
    return daemon::HttpReply{boost::beast::http::status::ok, "application/json", plots, {}};
  };
  auto server = daemon::StatusServer::start(
      args.bind, static_cast<std::uint16_t>(args.port), [status = view->status] { return status; },
      std::move(server_options));
  if (!server) {
    const bool bad_address = server.error().message.find("not an IP address") != std::string::npos;
    return fail(who, (bad_address ? "--bind: " : "") + server.error().message,
                bad_address ? kExitBadInput : kExitRuntime);
  }
  std::cout << who << "serving http://" << args.bind << ":" << (*server)->port() << "/"
            << std::endl;
  int signal = 0;
  sigwait(&stop_signals, &signal);
  return kExitOk;
}

}  // namespace

void registerViewCommand(CLI::App& app, int& exit_code) {
  const auto [command, args] = addSubcommand(
      app, "view",
      "Serve the in-cab page on a recorded session: coverage map, per-plot results, stem links",
      exit_code, runView);
  command->add_option("session", args->session, "Session folder")->required();
  command->add_option("--map", args->map,
                      "Map CSV (default: the map the session was recorded with)");
  command->add_option("--results", args->results,
                      "Results folder with plots.jsonl (default: SESSION/results)");
  command->add_option("--port", args->port, "TCP port (0: any free port)")
      ->capture_default_str()
      ->check(finiteRange(0, 65535));
  command->add_option("--bind", args->bind, "Address to listen on")->capture_default_str();
  command
      ->add_option("--stem-port", args->stem_port,
                   "Port of `fieldrig stem-ui` that the plots' stem links point to")
      ->capture_default_str()
      ->check(finiteRange(1, 65535));
}

}  // namespace fieldrig::tools
