// `fieldrig view SESSION` as the built binary: a session of three recorded plots
// (`fieldrig sim plots`), one of them processed (`fieldrig process --shard 0/3`), on a map with a
// location the run passed without a set and one it never reached. The status the page reads
// gives each location its state, /plots the processed plot with its stem link, and a missing or
// damaged session ends with exit 2 naming the path.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "support/cli_process.h"
#include "support/cli_run.h"
#include "support/http_client.h"
#include "support/temp_dir.h"

namespace fieldrig::testing_support {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// The port from the first stdout line, "fieldrig view: serving http://127.0.0.1:PORT/".
int servedPort(const std::string& line) {
  const std::string marker = "127.0.0.1:";
  const auto at = line.find(marker);
  return at == std::string::npos ? -1 : std::atoi(line.c_str() + at + marker.size());
}

HttpClientReply get(int port, const std::string& target) {
  HttpClient client(port);
  EXPECT_TRUE(client.send(httpRequestText("GET", target, {}, true)));
  return client.readReply();
}

// plot-1 … plot-3 as `sim plots` names them, with "gap" (passed without a set) between plot-1
// and plot-2, and "beyond" after the last: the session's map in the driving order.
void writeMap(const fs::path& path) {
  std::ofstream out(path);
  out << "id,lat,lon,heading,row\n"
         "plot-1,52.00000,5.00000,,1\n"
         "gap,52.00002,5.00000,,1\n"
         "plot-2,52.00004,5.00000,,1\n"
         "plot-3,52.00006,5.00000,,1\n"
         "beyond,52.00008,5.00000,,1\n";
}

class ViewCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ScopedTempDir("view_cli");
    session_ = dir_->path() / "session";
    const CliRun made =
        runFieldrig({"sim", "plots", "--out", session_.string(), "--count", "3"}, dir_->path());
    ASSERT_EQ(made.exit_code, 0) << made.err;
    // The first of the three sets only: the others stay recorded, not processed.
    const CliRun processed = runFieldrig(
        {"process", session_.string(), "--shard", "0/3", "--out", (session_ / "results").string()},
        dir_->path());
    ASSERT_EQ(processed.exit_code, 0) << processed.err;
    writeMap(dir_->path() / "map.csv");
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }

  static ScopedTempDir* dir_;
  static fs::path session_;
};

ScopedTempDir* ViewCli::dir_ = nullptr;
fs::path ViewCli::session_;

TEST_F(ViewCli, ServesEachLocationsStateThePlotsAndTheirStemLinks) {
  fs::create_directories(dir_->path() / "served");
  FieldrigProcess view({"view", session_.string(), "--map", (dir_->path() / "map.csv").string(),
                        "--port", "0", "--stem-port", "9123"},
                       dir_->path() / "served");
  ASSERT_TRUE(view.waitForStdoutLines(1, std::chrono::seconds{30})) << view.err();
  const int port = servedPort(view.outLines().front());
  ASSERT_GT(port, 0) << view.out();

  const HttpClientReply status_reply = get(port, "/status");
  ASSERT_EQ(status_reply.status, 200);
  const Json status = Json::parse(status_reply.body);
  EXPECT_EQ(status.at("mode"), "session");
  EXPECT_EQ(status.at("session"), "session");
  // plot-1 processed, gap missed, plot-2 and plot-3 recorded, beyond never reached.
  EXPECT_EQ(status.at("locations").at("states"), "pmrr.");
  EXPECT_EQ(status.at("triggers").at("missed"), 1);
  EXPECT_EQ(status.at("sets").at("recorded"), 3);
  EXPECT_EQ(status.at("sets").at("processed"), 1);

  const HttpClientReply map_reply = get(port, "/map");
  ASSERT_EQ(map_reply.status, 200);
  const Json map = Json::parse(map_reply.body);
  ASSERT_EQ(map.at("locations").size(), 5U);
  EXPECT_EQ(map.at("locations").at(1).at(0), "gap");
  EXPECT_EQ(map.at("locations").at(1).at(1), "1");

  const HttpClientReply plots_reply = get(port, "/plots");
  ASSERT_EQ(plots_reply.status, 200);
  const Json plots = Json::parse(plots_reply.body);
  ASSERT_EQ(plots.size(), 1U) << plots.dump();
  EXPECT_EQ(plots.at(0).at("location"), "plot-1");
  EXPECT_EQ(plots.at(0).at("set"), 0);
  EXPECT_EQ(plots.at(0).at("status"), "ok");
  EXPECT_GT(plots.at(0).at("height_m").get<double>(), 0.3);
  EXPECT_EQ(plots.at(0).at("stem_url"), "http://127.0.0.1:9123/?session=session&set=0");

  // The same page as fieldrigd's, and read-only.
  const HttpClientReply page = get(port, "/");
  ASSERT_EQ(page.status, 200);
  EXPECT_NE(page.body.find("fieldrig — in-cab"), std::string::npos);
  HttpClient poster(port);
  ASSERT_TRUE(poster.send(httpRequestText("POST", "/status", "{}", true)));
  EXPECT_EQ(poster.readReply().status, 405);

  ASSERT_TRUE(view.signal(SIGTERM));
  EXPECT_EQ(view.waitExit(), 0) << view.err();
}

TEST_F(ViewCli, AResultsFolderWithoutPlotsIsAnErrorNamingIt) {
  const fs::path empty = dir_->path() / "no-results";
  fs::create_directories(empty);
  fs::create_directories(dir_->path() / "served2");
  FieldrigProcess view({"view", session_.string(), "--map", (dir_->path() / "map.csv").string(),
                        "--results", empty.string(), "--port", "0"},
                       dir_->path() / "served2");
  // --results names a folder without plots.jsonl: an error naming it.
  EXPECT_EQ(view.waitExit(), 2);
  EXPECT_NE(view.err().find((empty / "plots.jsonl").string()), std::string::npos) << view.err();
}

TEST_F(ViewCli, AMissingOrDamagedSessionIsAnErrorNamingIt) {
  const fs::path missing = dir_->path() / "no-such-session";
  const CliRun absent = runFieldrig({"view", missing.string(), "--port", "0"}, dir_->path());
  EXPECT_EQ(absent.exit_code, 2);
  EXPECT_NE(absent.err.find(missing.string()), std::string::npos) << absent.err;

  // A session whose map cannot be found (sim plots records none): the error says to give --map.
  const CliRun no_map = runFieldrig({"view", session_.string(), "--port", "0"}, dir_->path());
  EXPECT_EQ(no_map.exit_code, 2);
  EXPECT_NE(no_map.err.find("--map"), std::string::npos) << no_map.err;

  // Damaged results: a line in the middle of plots.jsonl that is not a result.
  const fs::path damaged = dir_->path() / "damaged-results";
  fs::create_directories(damaged);
  std::ofstream(damaged / "plots.jsonl") << "{\"trigger_id\": 0}\nnot json\n{\"trigger_id\": 2}\n";
  const CliRun bad =
      runFieldrig({"view", session_.string(), "--map", (dir_->path() / "map.csv").string(),
                   "--results", damaged.string(), "--port", "0"},
                  dir_->path());
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find((damaged / "plots.jsonl").string() + ":2"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace fieldrig::testing_support
