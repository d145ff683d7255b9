// The NMEA player: the pacing on hand-made lines, then the transports (a file in real time and
// as fast as possible, a FIFO, a pseudo-terminal) delivering exactly the capture's lines.
#include "fieldrig/sim/nmea_player.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "fieldrig/gps/nmea_parser.h"
#include "support/temp_dir.h"

namespace fieldrig::sim {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using testing_support::ScopedTempDir;

std::string rmc(const std::string& time, const std::string& date = "140726") {
  return gps::withChecksum("GPRMC," + time + ",A,4807.038,N,01131.000,E,2.0,84.4," + date + ",,,D");
}
std::string gga(const std::string& time) {
  return gps::withChecksum("GPGGA," + time + ",4807.038,N,01131.000,E,4,12,0.8,500.0,M,47.0,M,,");
}

TEST(NmeaPacerTest, WaitsForTheGpsTimeBetweenEpochsAndNothingElse) {
  NmeaPacer pacer;
  EXPECT_EQ(pacer.waitBefore("# a gpsd log header"), 0ns);
  EXPECT_EQ(pacer.waitBefore(rmc("153000.00")), 0ns);         // the first epoch
  EXPECT_EQ(pacer.waitBefore(gga("153000.00") + "\r"), 0ns);  // the same epoch; CR ignored
  EXPECT_EQ(pacer.waitBefore(rmc("153000.10")), 100ms);
  EXPECT_EQ(pacer.waitBefore(gga("153000.10")), 0ns);
  EXPECT_EQ(pacer.waitBefore(gps::withChecksum("GPGSV,1,1,00")), 0ns);  // another sentence
  EXPECT_EQ(pacer.waitBefore("$GPRMC,garbage*00"), 0ns);                // a broken one
  EXPECT_EQ(pacer.waitBefore(gga("153000.50")), 400ms);
  EXPECT_EQ(pacer.waitBefore(rmc("153020.50")), 20s);  // a pause is played as it was
  // Time going back (another capture appended): no wait, and pacing goes on from there.
  EXPECT_EQ(pacer.waitBefore(rmc("152900.00")), 0ns);
  EXPECT_EQ(pacer.waitBefore(rmc("152901.25")), 1250ms);
}

TEST(NmeaPacerTest, ShortensLongPausesAndCrossesMidnight) {
  NmeaPacer pacer(5s);
  EXPECT_EQ(pacer.waitBefore(rmc("235959.90", "140726")), 0ns);
  EXPECT_EQ(pacer.waitBefore(rmc("000000.00", "150726")), 100ms);
  EXPECT_EQ(pacer.waitBefore(rmc("000130.00", "150726")), 5s);  // 90 s, shortened

  // GGA alone carries no date: the day rolls over when the time of day falls by half a day.
  NmeaPacer gga_only;
  EXPECT_EQ(gga_only.waitBefore(gga("235959.80")), 0ns);
  EXPECT_EQ(gga_only.waitBefore(gga("000000.05")), 250ms);
}

// ---- transports --------------------------------------------------------------------------------

struct Capture {
  std::string file_text;               // as written to disk: LF endings, a comment
  std::vector<std::string> delivered;  // what the player must deliver, line by line
};

// Three epochs 0.2 s apart.
Capture threeEpochs() {
  Capture capture;
  capture.file_text = "# capture\n";
  capture.delivered.push_back("# capture\r\n");
  for (const char* time : {"153000.00", "153000.20", "153000.40"}) {
    for (const std::string& line : {rmc(time), gga(time)}) {
      capture.file_text += line + "\n";
      capture.delivered.push_back(line + "\r\n");
    }
  }
  return capture;
}

struct Arrival {
  std::string bytes;
  Clock::time_point at;
};

TEST(NmeaPlayerTest, PlaysAFileLineByLineAtItsGpsTimes) {
  const ScopedTempDir dir("nmea_player_realtime");
  const Capture capture = threeEpochs();
  std::ofstream(dir / "drive.nmea", std::ios::binary) << capture.file_text;

  boost::asio::io_context io;
  std::vector<Arrival> arrivals;
  int ends = 0;
  auto player = NmeaPlayer::open(
      io, dir / "drive.nmea", NmeaPacing{},
      [&](std::string_view bytes) {
        arrivals.push_back({std::string(bytes), Clock::now()});
      },
      [&] { ++ends; });
  ASSERT_TRUE(player.ok()) << player.error().message;
  const auto started = Clock::now();
  (*player)->start();
  EXPECT_TRUE(arrivals.empty()) << "nothing is delivered inside start()";
  io.run();

  EXPECT_EQ(ends, 1);
  ASSERT_EQ(arrivals.size(), capture.delivered.size());
  for (std::size_t i = 0; i < arrivals.size(); ++i)
    EXPECT_EQ(arrivals[i].bytes, capture.delivered[i]) << i;
  // Epoch k (lines 1 + 2k, 2 + 2k) is due 0.2 k s after the start; never early, and late by
  // no more than a loaded machine's timer wake-up.
  for (int epoch = 0; epoch < 3; ++epoch) {
    const auto due = started + epoch * 200ms;
    for (int line = 1 + 2 * epoch; line <= 2 + 2 * epoch; ++line) {
      EXPECT_GE(arrivals[line].at, due) << line;
      EXPECT_LT(arrivals[line].at, due + 100ms) << line;
    }
  }
}

TEST(NmeaPlayerTest, NotInRealTimeTheFileComesAsFastAsItIsRead) {
  const ScopedTempDir dir("nmea_player_fast");
  std::string text;
  for (int second = 0; second < 60; ++second) {  // a minute of capture
    char time[24];  // room for any int: no format-truncation warning at any level
    std::snprintf(time, sizeof time, "1530%02d.00", second);
    text += rmc(time) + "\r\n" + gga(time) + "\r\n";
  }
  std::ofstream(dir / "drive.nmea", std::ios::binary) << text;
  boost::asio::io_context io;
  std::string received;
  bool ended = false;
  NmeaPacing pacing;
  pacing.realtime = false;
  auto player = NmeaPlayer::open(
      io, dir / "drive.nmea", pacing, [&](std::string_view bytes) { received += bytes; },
      [&] { ended = true; });
  ASSERT_TRUE(player.ok()) << player.error().message;
  (*player)->start();
  const auto started = Clock::now();
  io.run();
  EXPECT_LT(Clock::now() - started, 5s);
  EXPECT_TRUE(ended);
  EXPECT_EQ(received, text);  // byte for byte
}

TEST(NmeaPlayerTest, AFifoIsDeliveredAsItsWriterSendsItAndEndsWhenItCloses) {
  const ScopedTempDir dir("nmea_player_fifo");
  const std::string fifo = (dir / "gps.fifo").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string text = rmc("153000.00") + "\r\n" + gga("153000.00") + "\r\n";
  std::thread writer([&] {
    const int fd = ::open(fifo.c_str(), O_WRONLY);
    if (fd < 0)
      return;
    (void)!::write(fd, text.data(), 20);
    std::this_thread::sleep_for(50ms);
    (void)!::write(fd, text.data() + 20, text.size() - 20);
    ::close(fd);
  });
  boost::asio::io_context io;
  std::string received;
  bool ended = false;
  auto player = NmeaPlayer::open(  // meets the writer's open
      io, fifo, NmeaPacing{}, [&](std::string_view bytes) { received += bytes; },
      [&] { ended = true; });
  if (!player.ok()) {
    const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);  // release the writer
    writer.join();
    ::close(reader);
    FAIL() << player.error().message;
  }
  (*player)->start();
  io.run();
  writer.join();
  EXPECT_TRUE(ended);
  EXPECT_EQ(received, text);
}

TEST(NmeaPlayerTest, StoppedItDeliversNothingMore) {
  const ScopedTempDir dir("nmea_player_stop");
  const Capture capture = threeEpochs();
  std::ofstream(dir / "drive.nmea", std::ios::binary) << capture.file_text;
  boost::asio::io_context io;
  std::size_t deliveries = 0;
  bool ended = false;
  std::unique_ptr<NmeaPlayer> player;
  auto opened = NmeaPlayer::open(
      io, dir / "drive.nmea", NmeaPacing{},
      [&](std::string_view) {
        if (++deliveries == 3)  // the first epoch is out
          player->stop();
      },
      [&] { ended = true; });
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  player = std::move(*opened);
  player->start();
  io.run();
  EXPECT_EQ(deliveries, 3u);
  EXPECT_FALSE(ended);
}

TEST(NmeaPlayerTest, OpenErrorsNameThePath) {
  const ScopedTempDir dir("nmea_player_errors");
  boost::asio::io_context io;
  auto missing = NmeaPlayer::open(io, dir / "missing.nmea", NmeaPacing{}, {}, {});
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().message,
            (dir / "missing.nmea").string() + ": cannot open: No such file or directory");
  auto folder = NmeaPlayer::open(io, dir.path(), NmeaPacing{}, {}, {});
  ASSERT_FALSE(folder.ok());
  EXPECT_EQ(folder.error().message, dir.path().string() + ": not a file or FIFO");
}

TEST(NmeaPtyPlayerTest, WritesTheCaptureIntoItsPseudoTerminalAtItsPace) {
  const ScopedTempDir dir("nmea_pty_player");
  const Capture capture = threeEpochs();
  std::ofstream(dir / "drive.nmea", std::ios::binary) << capture.file_text;
  std::atomic<bool> ended{false};
  auto player = NmeaPtyPlayer::start(dir / "drive.nmea", NmeaPacing{}, [&] { ended = true; });
  ASSERT_TRUE(player.ok()) << player.error().message;
  const int fd = ::open((*player)->devicePath().c_str(), O_RDONLY | O_NOCTTY | O_CLOEXEC);
  ASSERT_GE(fd, 0) << (*player)->devicePath();

  std::string expected;
  for (const std::string& line : capture.delivered)
    expected += line;
  std::string received;
  std::vector<Clock::time_point> epoch_arrivals;  // when each RMC's first byte was read
  const auto deadline = Clock::now() + 10s;
  while (received.size() < expected.size() && Clock::now() < deadline) {
    pollfd ready{fd, POLLIN, 0};
    if (::poll(&ready, 1, 100) <= 0)
      continue;
    char buffer[512];
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n <= 0)
      break;
    const std::string chunk(buffer, static_cast<std::size_t>(n));
    for (std::size_t at = chunk.find("$GPRMC"); at != std::string::npos;
         at = chunk.find("$GPRMC", at + 1)) {
      epoch_arrivals.push_back(Clock::now());
    }
    received += chunk;
  }
  ::close(fd);
  EXPECT_EQ(received, expected);  // raw: no line-discipline translation
  ASSERT_EQ(epoch_arrivals.size(), 3u);
  EXPECT_GE(epoch_arrivals[1] - epoch_arrivals[0], 150ms);  // 200 ms apart, read a bit late
  EXPECT_GE(epoch_arrivals[2] - epoch_arrivals[1], 150ms);
  // on_end comes once the last fixes have had their time.
  const auto end_deadline = Clock::now() + 5s;
  while (!ended && Clock::now() < end_deadline)
    std::this_thread::sleep_for(10ms);
  EXPECT_TRUE(ended);
}

}  // namespace
}  // namespace fieldrig::sim
