#include "fieldrig/gps/live_trigger_chain.h"

#include <algorithm>

namespace fieldrig::gps {
namespace {
// Offsets of the last ~5 s of fixes at 10 Hz: long enough to contain a least-delayed fix,
// short enough to follow the slow drift between the receiver's and the host's clocks.
constexpr std::size_t kOffsetWindow = 50;
}  // namespace

core::Result<std::unique_ptr<LiveTriggerChain>> LiveTriggerChain::create(
    boost::asio::io_context& io, const LocationMap& map, TriggerChainOptions options,
    LiveTriggerHandlers handlers) {
  core::Result<TriggerPlanner> planner = TriggerPlanner::create(map, options.planner);
  if (!planner)
    return planner.error();
  return std::unique_ptr<LiveTriggerChain>(
      new LiveTriggerChain(io, std::move(*planner), options, std::move(handlers)));
}

LiveTriggerChain::LiveTriggerChain(boost::asio::io_context& io, TriggerPlanner planner,
                                   TriggerChainOptions options, LiveTriggerHandlers handlers)
    : timer_(io), options_(options), handlers_(std::move(handlers)), planner_(std::move(planner)) {}

std::optional<core::UtcTime> LiveTriggerChain::gpsTimeAt(core::SteadyTime steady) const {
  if (!offset_)
    return std::nullopt;
  return core::UtcTime{steady.time_since_epoch() - *offset_};
}

void LiveTriggerChain::onSentence(const Sentence& sentence, const core::ReceptionStamp& received) {
  if (stopped_)
    return;
  const std::optional<core::GpsFix> fix = assembler_.add(sentence, received);
  if (!fix)
    return;
  if (handlers_.on_fix)
    handlers_.on_fix(*fix);
  // Fire what was due before this fix arrived: the timer may not have run yet.
  fireDue(received.steady);

  recent_offsets_.push_back(received.steady.time_since_epoch() - fix->time.time_since_epoch());
  if (recent_offsets_.size() > kOffsetWindow)
    recent_offsets_.pop_front();
  const core::Nanoseconds least_delayed =
      *std::min_element(recent_offsets_.begin(), recent_offsets_.end());
  offset_ = least_delayed - core::fromSeconds(options_.latency_s);

  planner_.addFix(*fix, *gpsTimeAt(received.steady));
  fireDue(received.steady);
  armTimer();
}

void LiveTriggerChain::fireDue(core::SteadyTime now) {
  const std::optional<core::UtcTime> gps_now = gpsTimeAt(now);
  if (!gps_now)
    return;
  for (const core::TriggerEvent& event : planner_.collectDue(*gps_now)) {
    if (handlers_.on_trigger)
      handlers_.on_trigger(event, now);
  }
  for (const PlannerAlarm& alarm : planner_.takeAlarms()) {
    if (handlers_.on_alarm)
      handlers_.on_alarm(alarm);
  }
}

void LiveTriggerChain::armTimer() {
  const std::optional<core::UtcTime> next = planner_.nextTriggerTime();
  if (!next || !offset_) {
    timer_.cancel();
    return;
  }
  timer_.expires_at(core::SteadyTime{
      std::chrono::duration_cast<core::SteadyTime::duration>(next->time_since_epoch() + *offset_)});
  // A wait that completed just before the chain was stopped or destroyed may still be queued:
  // it checks the token and the flag before touching the chain.
  timer_.async_wait(
      [this, alive = std::weak_ptr<char>(alive_)](const boost::system::error_code& error) {
        if (error || alive.expired() || stopped_)
          return;  // cancelled (re-armed by a newer plan), stopped, or destroyed
        fireDue(std::chrono::steady_clock::now());
        armTimer();
      });
}

void LiveTriggerChain::stop() {
  stopped_ = true;
  timer_.cancel();
}

}  // namespace fieldrig::gps
