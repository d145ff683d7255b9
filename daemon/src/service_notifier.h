// systemd's notification protocol (sd_notify, libsystemd): READY once the daemon takes fixes,
// STATUS lines an operator sees in `systemctl status`, STOPPING on shutdown, and WATCHDOG pings
// from the GPS/trigger thread's own event loop, so a stalled GPS thread is what the watchdog
// catches. Without libsystemd, or outside systemd (no NOTIFY_SOCKET), every call does nothing.
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

#include <memory>
#include <string>

namespace fieldrig::daemon {

class ServiceNotifier {
 public:
  void ready();
  void status(const std::string& text);
  void stopping();
  // Pings at half the unit's WatchdogSec from `io`'s thread while it runs.
  void startWatchdog(boost::asio::io_context& io);

 private:
  void ping();
  std::unique_ptr<boost::asio::steady_timer> watchdog_timer_;
};

}  // namespace fieldrig::daemon
