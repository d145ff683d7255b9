// `fieldrig stem-ui SESSION_DIR… [--port P] [--bind A] [--calib DIR] [--out CSV]`: serves the stem
// measurement page (tools/stem_page) for the field team on a local port until interrupted. The
// first stdout line names the URL (tests and scripts read the port from it, useful with --port 0).
// Exit codes: 2 a session that cannot be opened or a bad --bind/--port; 3 cannot listen.
#include <boost/asio/ip/address.hpp>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands/command_helpers.h"
#include "fieldrig/daemon/http_server.h"
#include "stem_page/stem_page.h"

namespace fieldrig::tools {
namespace {

struct StemUiArgs {
  stem_page::StemPageOptions page;
  int port = 8765;
  std::string bind = "127.0.0.1";
};

int runStemUi(const StemUiArgs& args) {
  const char* who = "fieldrig stem-ui: ";
  auto page = stem_page::StemPage::open(args.page);
  if (!page)
    return fail(who, page.error().message);
  boost::system::error_code ec;
  const boost::asio::ip::address address = boost::asio::ip::make_address(args.bind, ec);
  if (ec) {
    std::cerr << who << "--bind: '" << args.bind << "' is not an IP address\n";
    return kExitBadInput;
  }
  if (args.port < 0 || args.port > 65535) {
    std::cerr << who << "--port: " << args.port << " is not a port\n";
    return kExitBadInput;
  }
  auto server = daemon::HttpServer::listen(address, static_cast<std::uint16_t>(args.port),
                                           {.name = "fieldrig stem-ui"});
  if (!server)
    return fail(who, server.error().message, kExitRuntime);
  std::cout << who << "serving http://" << args.bind << ":" << (*server)->port() << "/"
            << std::endl;
  (*server)->run([&page](const daemon::HttpRequest& request) { return (*page)->handle(request); });
  return kExitOk;
}

}  // namespace

void registerStemUiCommand(CLI::App& app, int& exit_code) {
  const auto [command, args] = addSubcommand(
      app, "stem-ui",
      "Serve the stem measurement page for recorded sessions (http://127.0.0.1:PORT/)", exit_code,
      runStemUi);
  command->add_option("sessions", args->page.sessions, "Session folders")->required();
  command->add_option("--port", args->port, "TCP port (0: any free port)")
      ->capture_default_str()
      ->check(finiteRange(0, 65535));
  command->add_option("--bind", args->bind, "Address to listen on")->capture_default_str();
  command->add_option("--calib", args->page.calib,
                      "Calibration folder: DIR/{bottom,middle,top}/{intrinsics,extrinsics}.yml");
  command->add_option("--out", args->page.out,
                      "CSV of the measurements (default: SESSION_DIR/stem_measurements.csv)");
}

}  // namespace fieldrig::tools
