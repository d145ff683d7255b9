// The live GPS → trigger chain: sentences with reception stamps in, triggers out at the
// predicted crossing, on a steady_timer. Owned by one thread: every method and callback runs on
// the thread running the io_context (the daemon's GPS/trigger thread, which nothing blocks).
//
// GPS time and the host's steady clock are related through the fixes' reception stamps:
// reception = fix time + clock offset + latency. The latency varies (the receiver's computation,
// serial queueing); its least value over recent fixes is taken to be the configured nominal
// latency, which fixes the offset, so a trigger planned for GPS time t fires at steady time
// t + offset.
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

#include <deque>
#include <functional>
#include <memory>
#include <optional>

#include "fieldrig/core/result.h"
#include "fieldrig/core/trigger_event.h"
#include "fieldrig/gps/fix_assembler.h"
#include "fieldrig/gps/nmea_parser.h"
#include "fieldrig/gps/trigger_planner.h"

namespace fieldrig::gps {

// What the live chain reports, on the io thread; any may be empty.
struct LiveTriggerHandlers {
  std::function<void(const core::TriggerEvent&, core::SteadyTime fired_at)> on_trigger;
  std::function<void(const PlannerAlarm&)> on_alarm;
  std::function<void(const core::GpsFix&)> on_fix;
};

class LiveTriggerChain {
 public:
  // The map must outlive the chain; an empty map is an error.
  static core::Result<std::unique_ptr<LiveTriggerChain>> create(boost::asio::io_context& io,
                                                                const LocationMap& map,
                                                                TriggerChainOptions options,
                                                                LiveTriggerHandlers handlers);
  LiveTriggerChain(const LiveTriggerChain&) = delete;
  LiveTriggerChain& operator=(const LiveTriggerChain&) = delete;

  // Feed every sentence as it arrives (SerialNmeaSource's handler).
  void onSentence(const Sentence& sentence, const core::ReceptionStamp& received);

  // Ends triggering: the timer is cancelled and later sentences are ignored. Final.
  void stop();

  // GPS time corresponding to a steady-clock instant; nullopt before the first fix.
  std::optional<core::UtcTime> gpsTimeAt(core::SteadyTime steady) const;
  const TriggerPlanner& planner() const { return planner_; }

 private:
  LiveTriggerChain(boost::asio::io_context& io, TriggerPlanner planner, TriggerChainOptions options,
                   LiveTriggerHandlers handlers);
  void armTimer();
  void fireDue(core::SteadyTime now);

  boost::asio::steady_timer timer_;
  TriggerChainOptions options_;
  LiveTriggerHandlers handlers_;
  FixAssembler assembler_;
  TriggerPlanner planner_;
  std::deque<core::Nanoseconds> recent_offsets_;  // reception (steady) − fix time, per fix
  std::optional<core::Nanoseconds> offset_;       // steady − GPS time
  bool stopped_ = false;
  std::shared_ptr<char> alive_ = std::make_shared<char>();  // expires with the chain
};

}  // namespace fieldrig::gps
