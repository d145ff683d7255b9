// The replay's NMEA input on a real filesystem and a real FIFO: a regular file reads whole, what
// a pipe's writer has sent is read without the writer closing, and interrupt() ends a read that
// a writer keeping the FIFO open would otherwise block for ever.
#include "fieldrig/core/interruptible_input.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <future>
#include <string>

#include "support/temp_dir.h"

namespace fieldrig::core {
namespace {

using namespace std::chrono_literals;
using testing_support::ScopedTempDir;

// Declared after a future reading the input: ends the read first, so that a failed assertion
// does not leave the future's destructor waiting on a blocked reader.
struct InterruptOnExit {
  InterruptibleInput& input;
  ~InterruptOnExit() { input.interrupt(); }
};

TEST(InterruptibleInputTest, ARegularFileReadsWholeToItsEnd) {
  ScopedTempDir dir("interruptible_regular");
  const auto path = dir.path() / "drive.nmea";
  std::string text;
  for (int i = 0; i < 5000; ++i)  // several chunks
    text += "$GPRMC,line " + std::to_string(i) + "\n";
  std::ofstream(path) << text;
  auto input = InterruptibleInput::open(path);
  ASSERT_TRUE(input) << input.error().message;
  std::string read(std::istreambuf_iterator<char>((*input)->stream()), {});
  EXPECT_EQ(read, text);
  EXPECT_TRUE((*input)->readError().empty());
  EXPECT_FALSE((*input)->interrupted());
}

TEST(InterruptibleInputTest, AMissingFileOrAFolderIsNamed) {
  ScopedTempDir dir("interruptible_missing");
  auto missing = InterruptibleInput::open(dir.path() / "none.nmea");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("none.nmea: cannot open"), std::string::npos)
      << missing.error().message;
  auto folder = InterruptibleInput::open(dir.path());
  ASSERT_FALSE(folder);
  EXPECT_NE(folder.error().message.find("a folder, not a file"), std::string::npos)
      << folder.error().message;
}

class InterruptibleInputFifoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(::mkfifo(fifo_.c_str(), 0600), 0);
    // Read and write: the writer's end is open before the reader's (a logger already running).
    writer_ = ::open(fifo_.c_str(), O_RDWR | O_CLOEXEC);
    ASSERT_GE(writer_, 0);
  }
  void TearDown() override {
    if (writer_ >= 0)
      ::close(writer_);
  }
  ScopedTempDir dir_{"interruptible_fifo"};
  std::filesystem::path fifo_ = dir_.path() / "drive.fifo";
  int writer_ = -1;
};

TEST_F(InterruptibleInputFifoTest, WhatTheWriterSentIsReadWhileItKeepsTheFifoOpen) {
  auto input = InterruptibleInput::open(fifo_);
  ASSERT_TRUE(input) << input.error().message;
  const std::string line = "$GPRMC,first\n";
  ASSERT_EQ(::write(writer_, line.data(), line.size()), static_cast<ssize_t>(line.size()));
  auto reading = std::async(std::launch::async, [&] {
    std::string got;
    std::getline((*input)->stream(), got);
    return got;
  });
  const InterruptOnExit interrupt_on_exit{**input};
  // The line is there at once; a reader wanting a whole chunk would still be waiting.
  ASSERT_EQ(reading.wait_for(10s), std::future_status::ready);
  EXPECT_EQ(reading.get(), "$GPRMC,first");
}

TEST_F(InterruptibleInputFifoTest, AnInterruptEndsAReadTheOpenWriterWouldBlockForEver) {
  auto input = InterruptibleInput::open(fifo_);
  ASSERT_TRUE(input) << input.error().message;
  auto reading = std::async(std::launch::async, [&] {
    std::string got;
    const bool any = static_cast<bool>(std::getline((*input)->stream(), got));
    return any;
  });
  const InterruptOnExit interrupt_on_exit{**input};
  EXPECT_EQ(reading.wait_for(200ms), std::future_status::timeout) << "nothing was written";
  (*input)->interrupt();
  ASSERT_EQ(reading.wait_for(10s), std::future_status::ready) << "the interrupt did not end it";
  EXPECT_FALSE(reading.get());
  EXPECT_TRUE((*input)->interrupted());
  EXPECT_TRUE((*input)->readError().empty()) << (*input)->readError();
}

TEST_F(InterruptibleInputFifoTest, TheWriterClosingIsTheEnd) {
  auto input = InterruptibleInput::open(fifo_);
  ASSERT_TRUE(input) << input.error().message;
  const std::string text = "$GPRMC,a\n$GPGGA,b\n";
  ASSERT_EQ(::write(writer_, text.data(), text.size()), static_cast<ssize_t>(text.size()));
  ::close(writer_);
  writer_ = -1;
  auto reading = std::async(std::launch::async, [&] {
    return std::string(std::istreambuf_iterator<char>((*input)->stream()), {});
  });
  const InterruptOnExit interrupt_on_exit{**input};
  ASSERT_EQ(reading.wait_for(10s), std::future_status::ready);
  EXPECT_EQ(reading.get(), text);
}

// `fieldrigd replay --nmea FIFO` started before the logger that writes it: the replay waits for
// the writer instead of taking the FIFO for an empty file.
TEST(InterruptibleInputTest, AFifoWithNoWriterYetIsWaitedFor) {
  ScopedTempDir dir("interruptible_no_writer");
  const auto fifo = dir.path() / "drive.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto input = InterruptibleInput::open(fifo);  // returns at once, with no writer
  ASSERT_TRUE(input) << input.error().message;
  auto reading = std::async(std::launch::async, [&] {
    std::string got;
    std::getline((*input)->stream(), got);
    return got;
  });
  const InterruptOnExit interrupt_on_exit{**input};
  EXPECT_EQ(reading.wait_for(600ms), std::future_status::timeout) << "no writer yet: not the end";
  const int writer = ::open(fifo.c_str(), O_WRONLY | O_CLOEXEC);
  ASSERT_GE(writer, 0);
  const std::string line = "$GPGGA,late\n";
  EXPECT_EQ(::write(writer, line.data(), line.size()), static_cast<ssize_t>(line.size()));
  ::close(writer);
  ASSERT_EQ(reading.wait_for(10s), std::future_status::ready);
  EXPECT_EQ(reading.get(), "$GPGGA,late");
}

// `printf '' | fieldrigd replay --nmea /dev/stdin`: an anonymous pipe whose writer has already
// gone is the end at once, not a FIFO waiting for a writer to come.
TEST(InterruptibleInputTest, AnEmptyPipeWhoseWriterHasGoneIsTheEnd) {
  int ends[2];
  ASSERT_EQ(::pipe2(ends, O_CLOEXEC), 0);
  ::close(ends[1]);
  auto input = InterruptibleInput::open("/proc/self/fd/" + std::to_string(ends[0]));
  ::close(ends[0]);
  ASSERT_TRUE(input) << input.error().message;
  auto reading = std::async(std::launch::async, [&] {
    std::string got;
    return static_cast<bool>(std::getline((*input)->stream(), got));
  });
  const InterruptOnExit interrupt_on_exit{**input};
  ASSERT_EQ(reading.wait_for(10s), std::future_status::ready) << "an empty pipe never ended";
  EXPECT_FALSE(reading.get());
  EXPECT_FALSE((*input)->interrupted());
}

// A logger that opens the FIFO after the replay did, and closes it without a line.
TEST(InterruptibleInputTest, AFifoWhoseWriterCameAndWentWithoutWritingIsTheEnd) {
  ScopedTempDir dir("interruptible_silent_writer");
  const auto fifo = dir.path() / "drive.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto input = InterruptibleInput::open(fifo);
  ASSERT_TRUE(input) << input.error().message;
  auto reading = std::async(std::launch::async, [&] {
    std::string got;
    return static_cast<bool>(std::getline((*input)->stream(), got));
  });
  const InterruptOnExit interrupt_on_exit{**input};
  const int writer = ::open(fifo.c_str(), O_WRONLY | O_CLOEXEC);
  ASSERT_GE(writer, 0);
  ::close(writer);
  ASSERT_EQ(reading.wait_for(10s), std::future_status::ready) << "the writer's leaving was missed";
  EXPECT_FALSE(reading.get());
  EXPECT_FALSE((*input)->interrupted());
}

}  // namespace
}  // namespace fieldrig::core
