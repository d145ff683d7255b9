// Where `fieldrig process` and the daemon keep a session's results: the default folder (one per
// shard) and the files a fresh run (--force) removes.
#include <gtest/gtest.h>

#include <fstream>

#include "fieldrig/daemon/results_writer.h"
#include "fieldrig/daemon/session_processing.h"
#include "support/temp_dir.h"

namespace fieldrig::daemon {
namespace {

namespace fs = std::filesystem;

TEST(ResultsFiles, DefaultFolderIsTheSessionsResultsAndOneFolderPerShard) {
  SessionProcessingOptions whole;
  EXPECT_EQ(defaultResultsDir("/data/s1", whole), fs::path("/data/s1/results"));
  SessionProcessingOptions one_shard;
  one_shard.shard_count = 1;
  EXPECT_EQ(defaultResultsDir("/data/s1", one_shard), fs::path("/data/s1/results"));
  SessionProcessingOptions shard;
  shard.shard_index = 2;
  shard.shard_count = 5;
  EXPECT_EQ(defaultResultsDir("/data/s1", shard), fs::path("/data/s1/results/shard-2-of-5"));
}

TEST(ResultsFiles, RemoveResultsTakesTheResultsFilesOnly) {
  testing_support::ScopedTempDir tmp("results_remove");
  const fs::path dir = tmp / "results";
  fs::create_directories(dir);
  const ResultsFiles files = resultsFiles(dir);
  EXPECT_EQ(files.jsonl, dir / "plots.jsonl");
  EXPECT_EQ(files.csv, dir / "plots.csv");
  EXPECT_EQ(files.geojson, dir / "plots.geojson");
  EXPECT_EQ(files.source, dir / "source.json");
  for (const fs::path& file :
       {files.jsonl, files.csv, files.geojson, files.source, dir / "plot-1_set0.ply"})
    std::ofstream(file) << "x\n";
  removeResults(dir);
  EXPECT_FALSE(fs::exists(files.jsonl));
  EXPECT_FALSE(fs::exists(files.csv));
  EXPECT_FALSE(fs::exists(files.geojson));
  EXPECT_FALSE(fs::exists(files.source));
  EXPECT_TRUE(fs::exists(dir / "plot-1_set0.ply"));
  removeResults(dir);  // nothing left to remove is not a failure
  removeResults(tmp / "no-such-folder");
}

}  // namespace
}  // namespace fieldrig::daemon
