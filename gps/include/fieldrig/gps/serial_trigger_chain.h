// The receiver's serial port feeding the live trigger chain: what `fieldrigd run`, the daemon's
// real-time replay and `fieldrig triggers` on a device all start. Owned by one thread: create,
// start, stop and destroy it, and receive its callbacks, on the thread running the io_context.
#pragma once

#include <boost/asio/io_context.hpp>

#include <memory>

#include "fieldrig/core/result.h"
#include "fieldrig/gps/live_trigger_chain.h"
#include "fieldrig/gps/serial_nmea_source.h"

namespace fieldrig::gps {

class SerialTriggerChain {
 public:
  // Opens nothing yet; errors are the chain's (empty map) and the source's (options).
  static core::Result<SerialTriggerChain> create(boost::asio::io_context& io,
                                                 const LocationMap& map, SerialOptions serial,
                                                 TriggerChainOptions triggers,
                                                 LiveTriggerHandlers handlers,
                                                 SerialNmeaSource::StatusHandler on_serial = {});

  void start() { source_->start(); }
  // Closes the port and ends triggering; no callback is made after it returns.
  void stop() {
    source_->stop();
    chain_->stop();
  }

  const NmeaStats& nmeaStats() const { return source_->stats(); }
  const TriggerStats& plannerStats() const { return chain_->planner().stats(); }

 private:
  SerialTriggerChain(std::unique_ptr<LiveTriggerChain> chain,
                     std::unique_ptr<SerialNmeaSource> source)
      : chain_(std::move(chain)), source_(std::move(source)) {}

  std::unique_ptr<LiveTriggerChain> chain_;
  std::unique_ptr<SerialNmeaSource> source_;  // feeds chain_: declared after it, destroyed first
};

}  // namespace fieldrig::gps
