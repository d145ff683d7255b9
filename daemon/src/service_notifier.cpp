#include "service_notifier.h"

#include <chrono>

#ifdef FIELDRIG_HAVE_SYSTEMD
#include <systemd/sd-daemon.h>
#endif

namespace fieldrig::daemon {
namespace {

void notify(const std::string& message) {
#ifdef FIELDRIG_HAVE_SYSTEMD
  sd_notify(0, message.c_str());
#else
  (void)message;
#endif
}

}  // namespace

void ServiceNotifier::ready() {
  notify("READY=1");
}

void ServiceNotifier::status(const std::string& text) {
  notify("STATUS=" + text);
}

void ServiceNotifier::stopping() {
  notify("STOPPING=1");
}

void ServiceNotifier::startWatchdog(boost::asio::io_context& io) {
#ifdef FIELDRIG_HAVE_SYSTEMD
  std::uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) <= 0 || usec == 0)
    return;
  watchdog_timer_ = std::make_unique<boost::asio::steady_timer>(io);
  const auto period = std::chrono::microseconds{usec / 2};
  auto arm = std::make_shared<std::function<void()>>();
  *arm = [this, period, arm] {
    watchdog_timer_->expires_after(period);
    watchdog_timer_->async_wait([this, arm](const boost::system::error_code& error) {
      if (error)
        return;
      ping();
      (*arm)();
    });
  };
  ping();
  (*arm)();
#else
  (void)io;
#endif
}

void ServiceNotifier::ping() {
  notify("WATCHDOG=1");
}

}  // namespace fieldrig::daemon
