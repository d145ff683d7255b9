// SerialNmeaSource against a real pseudo-terminal pair made by socat: the source reads one end
// (standing in for /dev/ttyUSB0), the test writes NMEA into the other. Killing socat is an unplug,
// restarting it with the same link names is a replug.
#include "fieldrig/gps/serial_nmea_source.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/post.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "fieldrig/gps/nmea_parser.h"
#include "support/socat_pty.h"

namespace fieldrig::gps {
namespace {

using testing_support::Feed;
using Socat = testing_support::SocatPty;

using namespace std::chrono_literals;
namespace fs = std::filesystem;

// Every wait is bounded by this; generous because the test machine is shared and small. A passing
// run waits far less (the whole file takes a few seconds).
constexpr auto kTimeout = 10s;

// ---- NMEA test data ---------------------------------------------------------------------------

// Sentence i of a 10 Hz stream: GGA and RMC alternate, each with its own time and latitude, so
// that a reordered, duplicated or spliced sentence cannot compare equal to the one expected.
std::string sentence(int i) {
  const int tenths = i / 2;
  const std::string time = fmt::format("10{:02}{:02}.{:02}", (tenths / 600) % 60,
                                       (tenths / 10) % 60, (tenths % 10) * 10);
  if (i % 2 == 0) {
    return withChecksum(fmt::format(
        "GPGGA,{},3842.{:08},N,11705.43645510,W,2,09,1.5,1864.182,M,-44.296,M,1.4,0000", time, i));
  }
  return withChecksum(
      fmt::format("GPRMC,{},A,3842.{:08},N,11705.43645510,W,0.011,46.405,231122,,,D", time, i));
}

std::string stream(int first, int count) {
  std::string bytes;
  for (int i = first; i < first + count; ++i)
    bytes += sentence(i) + "\r\n";
  return bytes;
}

std::vector<std::string> texts(int first, int count) {
  std::vector<std::string> out;
  for (int i = first; i < first + count; ++i)
    out.push_back(sentence(i));
  return out;
}

// ---- what the source reports ------------------------------------------------------------------

struct Received {
  SentenceKind kind;
  RejectReason reason;
  std::string text;
  core::ReceptionStamp stamp;
  std::uint64_t seq;  // position among sentences and statuses together
};

struct Status {
  SerialStatus status;
  std::uint64_t seq;
};

// Filled on the io thread, read by the test thread.
class Recorder {
 public:
  void onSentence(const Sentence& s, const core::ReceptionStamp& stamp) {
    std::lock_guard lock(mutex_);
    sentences_.push_back({s.kind, s.reason, std::string(s.text), stamp, seq_++});
    changed_.notify_all();
  }
  void onStatus(const SerialStatus& status) {
    std::lock_guard lock(mutex_);
    statuses_.push_back({status, seq_++});
    changed_.notify_all();
  }

  // Waits until pred(sentences, statuses) holds; false on timeout.
  template <typename Pred>
  bool waitUntil(Pred pred, std::chrono::milliseconds timeout = kTimeout) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return pred(sentences_, statuses_); });
  }

  std::vector<Received> sentences() const {
    std::lock_guard lock(mutex_);
    return sentences_;
  }
  std::vector<Status> statuses() const {
    std::lock_guard lock(mutex_);
    return statuses_;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<Received> sentences_;  // guarded by mutex_
  std::vector<Status> statuses_;     // guarded by mutex_
  std::uint64_t seq_ = 0;            // guarded by mutex_
};

std::size_t countEvents(const std::vector<Status>& statuses, SerialEvent event) {
  return static_cast<std::size_t>(std::count_if(
      statuses.begin(), statuses.end(), [&](const Status& s) { return s.status.event == event; }));
}

std::vector<std::string> acceptedTexts(const std::vector<Received>& sentences) {
  std::vector<std::string> out;
  for (const Received& r : sentences) {
    if (r.kind != SentenceKind::kRejected)
      out.push_back(r.text);
  }
  return out;
}

bool containsText(const std::vector<Received>& sentences, std::string_view text) {
  return std::any_of(sentences.begin(), sentences.end(),
                     [&](const Received& r) { return r.text == text; });
}

// ---- fixture ----------------------------------------------------------------------------------

class SerialNmeaSourceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "fieldrig-serial-XXXXXX").string();
    ASSERT_NE(::mkdtemp(tmpl.data()), nullptr) << std::strerror(errno);
    dir_ = tmpl;
    socat_.emplace(dir_);
    io_thread_ = std::thread([this] { io_.run(); });
  }

  void TearDown() override {
    // Destroyed on the io thread while a read may be pending: the destructor must cope.
    onIo([this] { source_.reset(); });
    work_.reset();
    io_.stop();
    if (io_thread_.joinable())
      io_thread_.join();
    socat_.reset();
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // Runs f on the io thread (the source's owner) and waits for it.
  template <typename F>
  void onIo(F f) {
    std::promise<void> done;
    boost::asio::post(io_, [&] {
      f();
      done.set_value();
    });
    if (done.get_future().wait_for(kTimeout) != std::future_status::ready) {
      ADD_FAILURE() << "the io thread did not run a posted task";
      std::abort();  // f and done live on this stack; returning would leave them dangling
    }
  }

  template <typename T, typename F>
  T onIoGet(F f) {
    T value{};
    onIo([&] { value = f(); });
    return value;
  }

  void startSource(SerialOptions options) {
    onIo([&] {
      auto created = SerialNmeaSource::create(
          io_, std::move(options),
          [this](const Sentence& s, const core::ReceptionStamp& stamp) {
            recorder_.onSentence(s, stamp);
            if (on_sentence_hook_)
              on_sentence_hook_(s);
          },
          [this](const SerialStatus& status) { recorder_.onStatus(status); });
      ASSERT_TRUE(created.ok()) << created.error().message;
      source_ = std::move(*created);
      source_->start();
    });
  }

  SerialOptions ptyOptions() const {
    SerialOptions options;
    options.device = socat_->device().string();
    options.baud = 4800;
    options.reopen_initial_delay = 20ms;
    options.reopen_max_delay = 80ms;
    return options;
  }

  bool waitOpened(std::size_t times) {
    return recorder_.waitUntil([&](const auto&, const std::vector<Status>& statuses) {
      return countEvents(statuses, SerialEvent::kOpened) >= times;
    });
  }

  bool waitAccepted(std::size_t count) {
    return recorder_.waitUntil([&](const std::vector<Received>& sentences, const auto&) {
      return acceptedTexts(sentences).size() >= count;
    });
  }

  // The source's byte counter is read on its thread; polled because no callback reports it.
  bool waitBytesReceived(std::uint64_t bytes) {
    const auto deadline = std::chrono::steady_clock::now() + kTimeout;
    while (onIoGet<std::uint64_t>([&] { return source_->bytesReceived(); }) < bytes) {
      if (std::chrono::steady_clock::now() > deadline)
        return false;
      std::this_thread::sleep_for(2ms);
    }
    return true;
  }

  fs::path dir_;
  std::optional<Socat> socat_;
  boost::asio::io_context io_;
  boost::asio::executor_work_guard<boost::asio::io_context::executor_type> work_ =
      boost::asio::make_work_guard(io_);
  std::thread io_thread_;
  Recorder recorder_;
  std::unique_ptr<SerialNmeaSource> source_;  // created, used and destroyed on the io thread
  std::function<void(const Sentence&)> on_sentence_hook_;  // set and run on the io thread
};

TEST_F(SerialNmeaSourceTest, SentencesArriveWholeInOrderWithMonotonicStamps) {
  ASSERT_EQ(socat_->start(), "");
  startSource(ptyOptions());
  ASSERT_TRUE(waitOpened(1));
  Feed feed(socat_->feed());
  ASSERT_TRUE(feed.ok());

  constexpr int kCount = 400;
  const std::string bytes = stream(0, kCount);
  // The last chunk is written separately to know a time before which the last sentence cannot
  // have been complete.
  const std::size_t last_line = bytes.rfind('$');
  const auto before_first_write = std::chrono::steady_clock::now();
  ASSERT_TRUE(feed.writeChunked(std::string_view(bytes).substr(0, last_line + 5), 200us));
  const auto before_last_write = std::chrono::steady_clock::now();
  ASSERT_TRUE(feed.write(std::string_view(bytes).substr(last_line + 5)));
  ASSERT_TRUE(waitAccepted(kCount));

  const std::vector<Received> got = recorder_.sentences();
  EXPECT_EQ(acceptedTexts(got), texts(0, kCount));
  ASSERT_EQ(got.size(), static_cast<std::size_t>(kCount)) << "rejects appeared in a clean stream";
  for (int i = 0; i < kCount; ++i) {
    EXPECT_EQ(got[i].kind, i % 2 == 0 ? SentenceKind::kGga : SentenceKind::kRmc) << i;
  }
  EXPECT_GE(got.front().stamp.steady, before_first_write);
  EXPECT_GE(got.back().stamp.steady, before_last_write);
  for (std::size_t i = 1; i < got.size(); ++i) {
    ASSERT_GE(got[i].stamp.steady, got[i - 1].stamp.steady) << i;
    ASSERT_GE(got[i].stamp.system, got[i - 1].stamp.system) << i;
  }
  // Written over hundreds of milliseconds, so one stamp for all would mean stamping at the wrong
  // moment (or once per start).
  EXPECT_GT(got.back().stamp.steady - got.front().stamp.steady, 10ms);

  const NmeaStats stats = onIoGet<NmeaStats>([&] { return source_->stats(); });
  EXPECT_EQ(stats.sentences, static_cast<std::uint64_t>(kCount));
  EXPECT_EQ(stats.rmc, static_cast<std::uint64_t>(kCount / 2));
  EXPECT_EQ(stats.rejectedTotal(), 0u);
  EXPECT_EQ(onIoGet<std::uint64_t>([&] { return source_->bytesReceived(); }), bytes.size());
  const std::vector<Status> statuses = recorder_.statuses();
  ASSERT_EQ(statuses.size(), 1u);
  EXPECT_EQ(statuses[0].status.event, SerialEvent::kOpened);
  EXPECT_EQ(statuses[0].status.device, socat_->device().string());
  EXPECT_TRUE(onIoGet<bool>([&] { return source_->isOpen(); }));
}

TEST_F(SerialNmeaSourceTest, GarbageNulsAndTruncatedLinesAreRejectedAndSurvived) {
  ASSERT_EQ(socat_->start(), "");
  startSource(ptyOptions());
  ASSERT_TRUE(waitOpened(1));
  Feed feed(socat_->feed());
  ASSERT_TRUE(feed.ok());

  std::string bad_checksum = sentence(102);
  bad_checksum.back() = bad_checksum.back() == '0' ? '1' : '0';
  std::string nul_inside = sentence(104);
  nul_inside[10] = '\0';
  const std::string truncated = sentence(103).substr(0, 25);
  const std::string bytes =
      sentence(100) + "\r\n" +                             // accepted
      "line noise at 4800 baud\r\n" +                      // garbage
      std::string(5, '\0') + "\r\n" +                      // garbage (a NUL run)
      std::string("\0\xff", 2) + sentence(101) + "\r\n" +  // garbage prefix, then accepted
      truncated + "\r\n" +                                 // no checksum
      bad_checksum + "\r\n" +                              // bad checksum
      nul_inside + "\r\n" +                                // non-printable
      "\x13\x11\x03\x1a\x7f\r\n" +  // garbage: XOFF, XON, ^C, ^Z, DEL reach us on a raw line
      sentence(105) + "\n" + sentence(106) + "\r";  // accepted, LF and CR alone
  ASSERT_TRUE(feed.writeChunked(bytes, 100us));
  ASSERT_TRUE(waitAccepted(4));

  const std::vector<Received> got = recorder_.sentences();
  EXPECT_EQ(acceptedTexts(got),
            (std::vector<std::string>{sentence(100), sentence(101), sentence(105), sentence(106)}));
  const NmeaStats stats = onIoGet<NmeaStats>([&] { return source_->stats(); });
  const auto rejected = [&](RejectReason reason) {
    return stats.rejected[static_cast<std::size_t>(reason)];
  };
  EXPECT_EQ(rejected(RejectReason::kGarbage), 4u);
  EXPECT_EQ(rejected(RejectReason::kNoChecksum), 1u);
  EXPECT_EQ(rejected(RejectReason::kBadChecksum), 1u);
  EXPECT_EQ(rejected(RejectReason::kNonPrintable), 1u);
  EXPECT_EQ(stats.rejectedTotal(), 7u);
  // Rejected lines reach the consumer too, with their text.
  EXPECT_EQ(got.size(), 4u + 7u);
  EXPECT_TRUE(containsText(got, truncated));
  EXPECT_TRUE(containsText(got, bad_checksum));
  EXPECT_EQ(countEvents(recorder_.statuses(), SerialEvent::kLost), 0u);
}

TEST_F(SerialNmeaSourceTest, UnplugAndReplugAreReportedAndRecoveredWithoutGluing) {
  ASSERT_EQ(socat_->start(), "");
  const SerialOptions options = ptyOptions();
  startSource(options);
  ASSERT_TRUE(waitOpened(1));

  // The line being sent when the cable goes: with the rest sent after the replug, it would make
  // a complete, valid sentence if the source glued the two.
  const std::string spliced = sentence(200);
  const std::string head = spliced.substr(0, 30);
  const std::string tail = spliced.substr(30);
  std::string before = stream(0, 50);
  {
    Feed feed(socat_->feed());
    ASSERT_TRUE(feed.ok());
    ASSERT_TRUE(feed.writeChunked(before, 100us));
    ASSERT_TRUE(feed.write(head));
    ASSERT_TRUE(waitBytesReceived(before.size() + head.size()));
  }
  socat_->kill();

  // Unplugged: lost once, then failing opens with the delay doubling up to the maximum.
  ASSERT_TRUE(recorder_.waitUntil([](const auto&, const std::vector<Status>& statuses) {
    return countEvents(statuses, SerialEvent::kOpenFailed) >= 4;
  })) << "no retries reported after the unplug";
  {
    const std::vector<Status> statuses = recorder_.statuses();
    ASSERT_GE(statuses.size(), 6u);
    EXPECT_EQ(statuses[0].status.event, SerialEvent::kOpened);
    const SerialStatus& lost = statuses[1].status;
    EXPECT_EQ(lost.event, SerialEvent::kLost);
    EXPECT_FALSE(lost.message.empty());
    EXPECT_EQ(lost.device, options.device);
    EXPECT_EQ(lost.retry_in, options.reopen_initial_delay);
    const std::vector<std::chrono::milliseconds> expected_delays{40ms, 80ms, 80ms, 80ms};
    for (std::size_t k = 0; k < expected_delays.size(); ++k) {
      const SerialStatus& failed = statuses[2 + k].status;
      EXPECT_EQ(failed.event, SerialEvent::kOpenFailed) << k;
      EXPECT_EQ(failed.retry_in, expected_delays[k]) << k;
      EXPECT_EQ(failed.message, std::system_category().message(ENOENT)) << k;
    }
  }
  EXPECT_FALSE(onIoGet<bool>([&] { return source_->isOpen(); }));
  EXPECT_EQ(onIoGet<std::uint64_t>([&] { return source_->timesLost(); }), 1u);

  // Replugged: same path, a new pty behind it.
  ASSERT_EQ(socat_->start(), "");
  ASSERT_TRUE(waitOpened(2)) << "not reopened after the replug";
  {
    Feed feed(socat_->feed());
    ASSERT_TRUE(feed.ok());
    ASSERT_TRUE(feed.writeChunked(tail + "\r\n" + stream(50, 20), 100us));
    ASSERT_TRUE(waitAccepted(70));
  }

  const std::vector<Received> got = recorder_.sentences();
  EXPECT_EQ(acceptedTexts(got), texts(0, 70));
  EXPECT_FALSE(containsText(got, spliced)) << "the line cut by the unplug was glued to new data";
  // The cut line is reported as the truncated line it is, before the loss is reported…
  const auto cut =
      std::find_if(got.begin(), got.end(), [&](const Received& r) { return r.text == head; });
  ASSERT_NE(cut, got.end());
  EXPECT_EQ(cut->kind, SentenceKind::kRejected);
  EXPECT_EQ(cut->reason, RejectReason::kNoChecksum);
  EXPECT_LT(cut->seq, recorder_.statuses()[1].seq);
  // …and the rest, arriving first after the replug, as garbage of its own.
  const auto rest =
      std::find_if(got.begin(), got.end(), [&](const Received& r) { return r.text == tail; });
  ASSERT_NE(rest, got.end());
  EXPECT_EQ(rest->kind, SentenceKind::kRejected);
  EXPECT_EQ(rest->reason, RejectReason::kGarbage);
  EXPECT_EQ(countEvents(recorder_.statuses(), SerialEvent::kLost), 1u);
}

TEST_F(SerialNmeaSourceTest, RestartAfterStopDoesNotGlueAndStoppedIsSilent) {
  ASSERT_EQ(socat_->start(), "");
  startSource(ptyOptions());
  ASSERT_TRUE(waitOpened(1));
  Feed feed(socat_->feed());
  ASSERT_TRUE(feed.ok());

  // stop() in the middle of a line, start() again, and the line's rest arrives first.
  const std::string spliced = sentence(7);
  const std::string head = spliced.substr(0, 20);
  ASSERT_TRUE(feed.write(stream(0, 3) + head));
  ASSERT_TRUE(waitBytesReceived(stream(0, 3).size() + head.size()));
  onIo([&] { source_->stop(); });
  EXPECT_FALSE(onIoGet<bool>([&] { return source_->isOpen(); }));
  onIo([&] { source_->start(); });
  ASSERT_TRUE(waitOpened(2));
  ASSERT_TRUE(feed.write(spliced.substr(20) + "\r\n" + sentence(8) + "\r\n"));
  ASSERT_TRUE(waitAccepted(4));

  std::vector<Received> got = recorder_.sentences();
  EXPECT_EQ(acceptedTexts(got),
            (std::vector<std::string>{sentence(0), sentence(1), sentence(2), sentence(8)}));
  EXPECT_FALSE(containsText(got, spliced)) << "the line cut by stop() was glued to new data";
  EXPECT_TRUE(containsText(got, head));

  // Stopped: nothing is read or reported, whatever the device sends.
  onIo([&] { source_->stop(); });
  const std::size_t before = got.size();
  ASSERT_TRUE(feed.write(stream(9, 3)));
  EXPECT_FALSE(recorder_.waitUntil([&](const std::vector<Received>& sentences,
                                       const auto&) { return sentences.size() > before; },
                                   100ms));
  EXPECT_EQ(countEvents(recorder_.statuses(), SerialEvent::kLost), 0u);
}

TEST_F(SerialNmeaSourceTest, StopFromInsideTheCallbackEndsCallbacksAtOnce) {
  ASSERT_EQ(socat_->start(), "");
  startSource(ptyOptions());
  ASSERT_TRUE(waitOpened(1));
  onIo([&] { on_sentence_hook_ = [this](const Sentence&) { source_->stop(); }; });
  Feed feed(socat_->feed());
  ASSERT_TRUE(feed.ok());
  // One write, so that the later sentences are most likely in the chunk being parsed.
  ASSERT_TRUE(feed.write(stream(0, 5)));
  ASSERT_TRUE(waitAccepted(1));
  EXPECT_FALSE(recorder_.waitUntil(
      [](const std::vector<Received>& sentences, const auto&) { return sentences.size() > 1; },
      100ms));
  EXPECT_FALSE(onIoGet<bool>([&] { return source_->running(); }));
  EXPECT_FALSE(onIoGet<bool>([&] { return source_->isOpen(); }));
}

TEST_F(SerialNmeaSourceTest, MissingDeviceIsRetriedWithBackoffUntilStopped) {
  SerialOptions options;
  options.device = (dir_ / "no-such-tty").string();
  options.baud = 9600;
  options.reopen_initial_delay = 10ms;
  options.reopen_max_delay = 40ms;
  startSource(options);

  ASSERT_TRUE(recorder_.waitUntil(
      [](const auto&, const std::vector<Status>& statuses) { return statuses.size() >= 5; }));
  const std::vector<Status> statuses = recorder_.statuses();
  const std::vector<std::chrono::milliseconds> expected_delays{10ms, 20ms, 40ms, 40ms, 40ms};
  for (std::size_t k = 0; k < expected_delays.size(); ++k) {
    EXPECT_EQ(statuses[k].status.event, SerialEvent::kOpenFailed) << k;
    EXPECT_EQ(statuses[k].status.device, options.device) << k;
    EXPECT_EQ(statuses[k].status.message, std::system_category().message(ENOENT)) << k;
    EXPECT_EQ(statuses[k].status.retry_in, expected_delays[k]) << k;
  }
  EXPECT_FALSE(onIoGet<bool>([&] { return source_->isOpen(); }));
  EXPECT_GE(onIoGet<std::uint64_t>([&] { return source_->openFailures(); }), 5u);

  onIo([&] { source_->stop(); });
  const std::size_t after_stop = recorder_.statuses().size();
  // Several maximum delays: a retry still armed would have reported by then.
  EXPECT_FALSE(recorder_.waitUntil(
      [&](const auto&, const std::vector<Status>& all) { return all.size() > after_stop; }, 150ms));
  EXPECT_FALSE(onIoGet<bool>([&] { return source_->running(); }));
}

// ---- a real receiver's capture replayed through the pty ---------------------------------------

class SerialReplayTest : public SerialNmeaSourceTest,
                         public ::testing::WithParamInterface<const char*> {};

TEST_P(SerialReplayTest, CaptureArrivesAsTheParserDecodesTheFile) {
  const fs::path path = fs::path(FIELDRIG_SHARED_DATA_DIR) / "nmea/gpsd" / GetParam();
  std::ifstream in(path, std::ios::binary);
  ASSERT_TRUE(in) << "cannot read " << path;
  const std::string file{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  // The '#' header lines were written by gpsd's maintainers, not sent by the receiver.
  std::string device_bytes;
  for (std::size_t pos = 0; pos < file.size();) {
    std::size_t end = file.find('\n', pos);
    end = end == std::string::npos ? file.size() : end + 1;
    if (file[pos] != '#')
      device_bytes.append(file, pos, end - pos);
    pos = end;
  }
  ASSERT_GT(device_bytes.size(), 1000u);

  std::vector<std::pair<SentenceKind, std::string>> expected;
  NmeaParser direct([&](const Sentence& s) { expected.emplace_back(s.kind, std::string(s.text)); });
  direct.feed(device_bytes);
  ASSERT_GT(direct.stats().rmc + direct.stats().gga, 20u);

  ASSERT_EQ(socat_->start(), "");
  SerialOptions options = ptyOptions();
  options.baud = 38400;  // what gpsd's regression driver replays these logs at
  startSource(options);
  ASSERT_TRUE(waitOpened(1));
  Feed feed(socat_->feed());
  ASSERT_TRUE(feed.ok());
  ASSERT_TRUE(feed.writeChunked(device_bytes, 0us));
  ASSERT_TRUE(waitBytesReceived(device_bytes.size()));
  ASSERT_TRUE(recorder_.waitUntil([&](const std::vector<Received>& sentences, const auto&) {
    return sentences.size() >= expected.size();
  }));

  std::vector<std::pair<SentenceKind, std::string>> got;
  for (const Received& r : recorder_.sentences())
    got.emplace_back(r.kind, r.text);
  EXPECT_EQ(got, expected);
  const NmeaStats live = onIoGet<NmeaStats>([&] { return source_->stats(); });
  EXPECT_EQ(live.lines, direct.stats().lines);
  EXPECT_EQ(live.sentences, direct.stats().sentences);
  EXPECT_EQ(live.rejected, direct.stats().rejected);
}

// "gp-320fw-2019-04-07-coldboot.log" -> "gp_320fw_2019_04_07_coldboot": a valid test name.
std::string captureName(const ::testing::TestParamInfo<const char*>& param) {
  std::string name = param.param;
  name = name.substr(0, name.find('.'));
  std::replace_if(
      name.begin(), name.end(),
      [](char c) { return std::isalnum(static_cast<unsigned char>(c)) == 0; }, '_');
  return name;
}

// A clean machine receiver, and one with NULs, truncated and merged lines.
INSTANTIATE_TEST_SUITE_P(GpsdCaptures, SerialReplayTest,
                         ::testing::Values("cat-ms352.log", "gp-320fw-2019-04-07-coldboot.log"),
                         captureName);

// ---- start-up errors --------------------------------------------------------------------------

TEST(SerialNmeaSourceOptions, NonStandardBaudRatesAreErrors) {
  boost::asio::io_context io;
  const auto make = [&](unsigned baud) {
    SerialOptions options;
    options.device = "/dev/ttyUSB0";
    options.baud = baud;
    return SerialNmeaSource::create(io, options,
                                    [](const Sentence&, const core::ReceptionStamp&) {});
  };
  for (unsigned baud : {0u, 300u, 2400u, 4801u, 14400u, 100000u, 230400u, 921600u}) {
    const auto source = make(baud);
    ASSERT_FALSE(source.ok()) << baud;
    EXPECT_EQ(source.error().message, "serial port /dev/ttyUSB0: unsupported baud rate " +
                                          std::to_string(baud) +
                                          " (use 4800, 9600, 19200, 38400, 57600 or 115200)");
  }
  for (unsigned baud : {4800u, 9600u, 19200u, 38400u, 57600u, 115200u}) {
    EXPECT_TRUE(make(baud).ok()) << baud;
  }
  // Creation opens nothing: an absent /dev/ttyUSB0 above is not an error until start().
  EXPECT_EQ(io.poll(), 0u);
}

TEST(SerialNmeaSourceOptions, EmptyDeviceAndBadDelaysAreErrors) {
  boost::asio::io_context io;
  const auto handler = [](const Sentence&, const core::ReceptionStamp&) {};
  SerialOptions options;
  auto source = SerialNmeaSource::create(io, options, handler);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.error().message, "serial port: empty device path");
  options.device = "/dev/ttyUSB0";
  options.reopen_initial_delay = 0ms;
  source = SerialNmeaSource::create(io, options, handler);
  ASSERT_FALSE(source.ok());
  EXPECT_NE(source.error().message.find("reopen delays must satisfy"), std::string::npos);
  options.reopen_initial_delay = 500ms;
  options.reopen_max_delay = 100ms;
  source = SerialNmeaSource::create(io, options, handler);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.error().message,
            "serial port /dev/ttyUSB0: reopen delays must satisfy 0 < initial (500 ms) <= max "
            "(100 ms)");
}

}  // namespace
}  // namespace fieldrig::gps
