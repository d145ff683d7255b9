// The live chain in real time: a simulated drive's sentences are delivered on an io_context at
// the pace of their GPS times plus a known latency; triggers must fire on the steady clock at
// the moment that corresponds to their planned GPS time. Creation errors of the chain and of the
// serial chain in front of it.
#include "fieldrig/gps/live_trigger_chain.h"

#include <gtest/gtest.h>

#include <boost/asio/steady_timer.hpp>
#include <sstream>

#include "fieldrig/gps/field_plan.h"
#include "fieldrig/gps/serial_trigger_chain.h"
#include "fieldrig/sim/drive_simulator.h"
#include "fieldrig/sim/trigger_accuracy.h"
#include "support/field_plans.h"

namespace fieldrig::gps {
namespace {

using namespace std::chrono_literals;

struct TimedLine {
  core::UtcTime time;
  std::string text;
};

TEST(LiveTriggerChainTest, FiresOnTheSteadyClockAtThePlannedGpsTime) {
  // One row about 12 m north, 2 m plots.
  const FieldPlan plan =
      testing_support::fieldPlan({42.0, -93.6}, {42.0 + 12.0 / 111'000.0, -93.6}, 1, 2.0);
  const auto map = generateLocations(plan);
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_EQ(map->size(), 4u);

  sim::DriveOptions drive_options;
  drive_options.speed_mps = 3.0;
  drive_options.headland_m = 3.0;
  const sim::DriveSimulator drive(plan, drive_options);

  // Sentences with the time of their epoch, to be delivered at that time + latency.
  std::vector<TimedLine> lines;
  {
    std::istringstream in(drive.nmea());
    std::string line;
    while (std::getline(in, line)) {
      const Sentence s = NmeaParser::parseLine(line.substr(0, line.size() - 1));
      ASSERT_TRUE(s.kind == SentenceKind::kRmc || s.kind == SentenceKind::kGga);
      const auto tod = s.kind == SentenceKind::kRmc ? s.rmc.time_of_day : s.gga.time_of_day;
      lines.push_back({std::chrono::floor<std::chrono::days>(drive.start()) + *tod, line});
    }
  }

  boost::asio::io_context io;
  const auto latency = 50ms;
  TriggerChainOptions options;
  options.latency_s = 0.05;
  struct Fired {
    core::TriggerEvent event;
    core::SteadyTime at;
  };
  std::vector<Fired> fired;
  LiveTriggerHandlers handlers;
  handlers.on_trigger = [&](const core::TriggerEvent& e, core::SteadyTime at) {
    fired.push_back({e, at});
  };
  auto created = LiveTriggerChain::create(io, *map, options, handlers);
  ASSERT_TRUE(created.ok()) << created.error().message;
  LiveTriggerChain& chain = **created;

  // GPS time t is delivered at steady time origin + (t - start) + latency.
  const core::SteadyTime origin = std::chrono::steady_clock::now() + 100ms;
  auto steadyFor = [&](core::UtcTime t) {
    return origin + std::chrono::duration_cast<core::SteadyTime::duration>(t - drive.start());
  };
  boost::asio::steady_timer feeder(io);
  std::size_t next = 0;
  std::function<void()> deliver = [&] {
    if (next >= lines.size())
      return;
    feeder.expires_at(steadyFor(lines[next].time) + latency);
    feeder.async_wait([&](const boost::system::error_code& error) {
      if (error)
        return;
      const core::ReceptionStamp stamp = core::ReceptionStamp::now();
      const std::string& text = lines[next].text;
      chain.onSentence(NmeaParser::parseLine(text.substr(0, text.size() - 1)), stamp);
      ++next;
      deliver();
    });
  };
  deliver();
  io.run_for(std::chrono::duration_cast<std::chrono::milliseconds>(
      core::fromSeconds(drive.lengthM() / drive_options.speed_mps) + 1s));

  ASSERT_EQ(fired.size(), map->size());
  std::vector<core::TriggerEvent> events;
  for (const Fired& f : fired) {
    events.push_back(f.event);
    // The timer fires when the planned GPS time comes round on the steady clock. Timer wake-up
    // on a loaded 2-core VM takes up to a few ms; 20 ms is 6 cm at 3 m/s.
    const auto lag = f.at - steadyFor(f.event.time);
    EXPECT_GE(lag, -1ms);
    EXPECT_LE(lag, 20ms);
    EXPECT_EQ(f.event.status, core::TriggerStatus::kOnTime);
  }
  const sim::TriggerAccuracy accuracy = sim::scoreTriggers(drive, *map, events);
  EXPECT_EQ(accuracy.fired_once, map->size());
  EXPECT_LT(accuracy.max_abs_m, 0.04);
}

TEST(LiveTriggerChainTest, AnEmptyMapIsAStartUpError) {
  boost::asio::io_context io;
  const LocationMap empty;
  const auto chain = LiveTriggerChain::create(io, empty, {}, {});
  ASSERT_FALSE(chain.ok());
  EXPECT_EQ(chain.error().message, "the imaging-location map has no locations");
}

TEST(SerialTriggerChainTest, CreationReportsTheMapAndTheSerialOptionsAndOpensNothing) {
  boost::asio::io_context io;
  SerialOptions serial;
  serial.device = "/dev/ttyUSB0";
  auto chain = SerialTriggerChain::create(io, LocationMap{}, serial, {}, {});
  ASSERT_FALSE(chain.ok());
  EXPECT_EQ(chain.error().message, "the imaging-location map has no locations");

  LocationMap map;
  ImagingLocation location;
  location.id = "A";
  location.latitude_deg = 42.0;
  location.longitude_deg = -93.6;
  ASSERT_TRUE(map.add(location).ok());
  serial.baud = 2400;
  chain = SerialTriggerChain::create(io, map, serial, {}, {});
  ASSERT_FALSE(chain.ok());
  EXPECT_EQ(chain.error().message.rfind("serial port /dev/ttyUSB0: unsupported baud rate 2400", 0),
            0u)
      << chain.error().message;

  serial.baud = 9600;
  chain = SerialTriggerChain::create(io, map, serial, {}, {});
  ASSERT_TRUE(chain.ok()) << chain.error().message;
  EXPECT_EQ(chain->nmeaStats().lines, 0u);
  EXPECT_EQ(chain->plannerStats().fixes, 0u);
  EXPECT_EQ(io.poll(), 0u);  // nothing opened before start()
}

}  // namespace
}  // namespace fieldrig::gps
