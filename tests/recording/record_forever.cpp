// Test helper: records synthetic FrameSets into a session folder until it is killed, printing
// "set N" after each set is written (indexed). The kill -9 test runs it and kills it mid-run.
//   record_forever DIR [none|per_set|per_frame]
#include <cstdio>
#include <string>

#include "fieldrig/recording/session_writer.h"
#include "recording/synthetic_sets.h"

int main(int argc, char** argv) {
  using namespace fieldrig;
  if (argc < 2) {
    std::fprintf(stderr, "usage: record_forever DIR [none|per_set|per_frame]\n");
    return 2;
  }
  recording::WriterOptions options;
  if (argc > 2) {
    const auto policy = recording::parseFsyncPolicy(argv[2]);
    if (!policy) {
      std::fprintf(stderr, "unknown fsync policy '%s'\n", argv[2]);
      return 2;
    }
    options.fsync = *policy;
  }
  recording::SessionWriter writer;
  recording::SessionInfo info;
  info.configuration = {{"helper", "record_forever"}};
  core::Result<recording::OpenReport> opened = writer.open(argv[1], info, options);
  if (!opened) {
    std::fprintf(stderr, "%s\n", opened.error().message.c_str());
    return 2;
  }
  // Big enough that a kill often lands inside a frame write, small enough to run many sets.
  testing_support::SyntheticRig rig(320, 240);
  for (std::uint64_t trigger = 1000 * (opened->next_set_index + 1);; ++trigger) {
    rig.fill(trigger);
    // append, not "L" + std::string: GCC 12 -O3 gives a false-positive -Wrestrict.
    const recording::WriteOutcome outcome =
        writer.write(rig.record(trigger, std::string("L").append(std::to_string(trigger % 7))));
    if (!outcome.ok()) {
      std::fprintf(stderr, "%s\n", outcome.message.c_str());
      return 3;
    }
    std::printf("set %llu\n", static_cast<unsigned long long>(outcome.set_index));
    std::fflush(stdout);
  }
}
