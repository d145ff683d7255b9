// `fieldrig triggers --nmea DEVICE` live: a simulated drive is written into a real pty (socat)
// at the pace of its GPS times; the CLI reads the other end as it would /dev/ttyUSB0 and must
// fire every location once, on time, until SIGINT.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "fieldrig/gps/field_plan.h"
#include "fieldrig/sim/drive_simulator.h"
#include "fieldrig/sim/trigger_accuracy.h"
#include "support/cli_process.h"
#include "support/cli_run.h"
#include "support/field_plans.h"
#include "support/socat_pty.h"
#include "support/temp_dir.h"

namespace fieldrig {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using Json = nlohmann::json;

TEST(TriggersLiveCliTest, FiresEveryLocationOnceFromASerialDevice) {
  const testing_support::ScopedTempDir dir("triggers_live");
  // Two rows about 10 m long, 2 m plots.
  const gps::FieldPlan plan =
      testing_support::fieldPlan({41.99, -93.64}, {41.99 + 10.0 / 111'000.0, -93.64}, 2, 2.0);
  const auto map = gps::generateLocations(plan);
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_TRUE(map->save(dir / "map.csv").ok());
  sim::DriveOptions options;
  options.speed_mps = 3.0;
  options.headland_m = 2.0;
  const sim::DriveSimulator drive(plan, options);

  testing_support::SocatPty pty(dir.path());
  const std::string started = pty.start();
  ASSERT_EQ(started, "") << started;

  testing_support::FieldrigProcess triggers(
      {"triggers", "--map", dir / "map.csv", "--nmea", pty.device()}, dir.path());
  std::this_thread::sleep_for(300ms);  // let it open the device

  // Write each epoch's sentences at its GPS time (relative to the drive's start).
  testing_support::Feed feed(pty.feed());
  ASSERT_TRUE(feed.ok());
  const auto lines = testing_support::splitLines(drive.nmea());
  const auto origin = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < lines.size(); i += 2) {
    const std::string epoch = lines[i] + "\n" + lines[i + 1] + "\n";
    std::this_thread::sleep_until(origin + std::chrono::milliseconds(50 * i));  // 10 Hz: 2 lines
    ASSERT_TRUE(feed.write(epoch));
  }
  std::this_thread::sleep_for(300ms);
  ASSERT_TRUE(triggers.signal(SIGINT)) << triggers.err();
  ASSERT_EQ(triggers.waitExit(), 0) << triggers.err();

  std::vector<core::TriggerEvent> events;
  for (const std::string& text : triggers.outLines()) {
    const Json line = Json::parse(text);
    core::TriggerEvent event;
    event.location_id = line["location"];
    event.time = *core::parseIso8601(line["time"].get<std::string>());
    events.push_back(event);
    EXPECT_TRUE(line.contains("host_time"));
  }
  const sim::TriggerAccuracy accuracy = sim::scoreTriggers(drive, *map, events);
  EXPECT_EQ(accuracy.fired_once, map->size()) << triggers.err();
  // The planned GPS times are as accurate as in replay; the host clock only decides when.
  EXPECT_LT(accuracy.max_abs_m, 0.04);
  const std::string log = triggers.err();
  EXPECT_NE(log.find("\"summary\""), std::string::npos) << log;
}

}  // namespace
}  // namespace fieldrig
