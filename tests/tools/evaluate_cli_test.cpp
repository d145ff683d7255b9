// `fieldrig evaluate RESULTS --truth TRUTH`, run as the built binary on results and truth files
// written here with known errors, so that every figure of the summary is known beforehand.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "support/cli_run.h"
#include "support/temp_dir.h"

namespace fieldrig {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using testing_support::runFieldrig;
using testing_support::ScopedTempDir;

// A results line as `fieldrig process` writes it (traits nested, plot and location ids).
std::string resultLine(const std::string& plot, const std::string& status, double height,
                       double width, double vvi) {
  return Json{
      {"set", 0},
      {"plot", plot},
      {"location", plot},
      {"traits", {{"status", status}, {"height_m", height}, {"width_m", width}, {"vvi", vvi}}}}
      .dump();
}

// A truth line as `fieldrig simulate` writes it (traits at the top).
std::string truthLine(const std::string& plot, double height, double width, double vvi) {
  return Json{{"plot", plot}, {"set", 0}, {"height_m", height}, {"width_m", width}, {"vvi", vvi}}
      .dump();
}

void writeLines(const fs::path& path, const std::vector<std::string>& lines) {
  std::ofstream out(path);
  for (const std::string& line : lines)
    out << line << '\n';
}

class EvaluateCli : public ::testing::Test {
 protected:
  ScopedTempDir dir{"evaluate_cli"};
  fs::path results_dir = dir.path() / "results";
  fs::path truth = dir.path() / "truth.jsonl";

  void SetUp() override {
    fs::create_directories(results_dir);
    writeLines(truth, {truthLine("A", 1.00, 0.50, 0.40), truthLine("B", 2.00, 0.80, 0.50),
                       truthLine("C", 1.50, 0.60, 0.20), truthLine("D", 1.20, 0.40, 0.30)});
    // A: +2 cm height, -4 cm width, +10 % VVI; B: -6 cm, +2 cm, -20 %; C failed (not scored);
    // D missing.
    writeLines(results_dir / "plots.jsonl",
               {resultLine("A", "ok", 1.02, 0.46, 0.44), resultLine("B", "ok", 1.94, 0.82, 0.40),
                resultLine("C", "no_ground", 0.0, 0.0, 0.0)});
  }
};

TEST_F(EvaluateCli, SummaryHoldsMeanMaxAndBiasOfTheScoredPlots) {
  const auto run =
      runFieldrig({"evaluate", results_dir.string(), "--truth", truth.string()}, dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json summary = Json::parse(run.out_lines.back()).at("summary");
  EXPECT_EQ(summary.at("plots"), 3);
  EXPECT_EQ(summary.at("scored"), 2);
  EXPECT_EQ(summary.at("not_ok"), Json::array({"C"}));
  EXPECT_EQ(summary.at("missing_in_results"), Json::array({"D"}));
  const Json& height = summary.at("height_m");
  EXPECT_EQ(height.at("plots"), 2);
  EXPECT_NEAR(height.at("mean_abs").get<double>(), 0.04, 1e-9);
  EXPECT_NEAR(height.at("max_abs").get<double>(), 0.06, 1e-9);
  EXPECT_NEAR(height.at("bias").get<double>(), -0.02, 1e-9);
  EXPECT_EQ(height.at("worst_plot"), "B");
  const Json& width = summary.at("width_m");
  EXPECT_NEAR(width.at("mean_abs").get<double>(), 0.03, 1e-9);
  EXPECT_NEAR(width.at("bias").get<double>(), -0.01, 1e-9);
  EXPECT_EQ(width.at("worst_plot"), "A");
  const Json& vvi = summary.at("vvi");  // relative to the truth
  EXPECT_EQ(vvi.at("unit"), "fraction of truth");
  EXPECT_NEAR(vvi.at("mean_abs").get<double>(), 0.15, 1e-9);
  EXPECT_NEAR(vvi.at("bias").get<double>(), -0.05, 1e-9);
  EXPECT_FALSE(summary.contains("vai")) << "neither side has VAI";
  // The table: a header and one row per plot in the results, errors in cm and %.
  ASSERT_EQ(run.out_lines.size(), 5u);
  EXPECT_NE(run.out_lines[1].find("2.0"), std::string::npos) << run.out_lines[1];
  EXPECT_NE(run.out_lines[2].find("-20.0"), std::string::npos) << run.out_lines[2];
  EXPECT_NE(run.out_lines[3].find("no_ground"), std::string::npos) << run.out_lines[3];
}

TEST_F(EvaluateCli, TruthAsAJsonArrayOrPlotsObjectReadsAsTheLinesDo) {
  const fs::path json_truth = dir.path() / "truth.json";
  std::ofstream(json_truth) << "{\"plots\": [" << truthLine("A", 1.00, 0.50, 0.40) << ","
                            << truthLine("B", 2.00, 0.80, 0.50) << "]}";
  const auto run = runFieldrig({"evaluate", (results_dir / "plots.jsonl").string(), "--truth",
                                json_truth.string(), "--summary-only"},
                               dir.path());
  // C has no truth in this file: the results are not of this field.
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("results plot C has no truth"), std::string::npos) << run.err;
  writeLines(results_dir / "plots.jsonl",
             {resultLine("A", "ok", 1.02, 0.46, 0.44), resultLine("B", "ok", 1.94, 0.82, 0.40)});
  const auto both = runFieldrig(
      {"evaluate", results_dir.string(), "--truth", json_truth.string(), "--summary-only"},
      dir.path());
  ASSERT_EQ(both.exit_code, 0) << both.err;
  ASSERT_EQ(both.out_lines.size(), 1u);
  EXPECT_NEAR(Json::parse(both.out_lines[0])["summary"]["height_m"]["max_abs"].get<double>(), 0.06,
              1e-9);
}

TEST_F(EvaluateCli, TruthViewScoresAgainstTheNamedBlockOfEachTruthLine) {
  // The mesh truth's other definitions sit in their own object: the stereo view's widths here
  // are 4 cm narrower than the seen view's, so A's width error becomes 0 and B's +6 cm.
  auto meshLine = [](const std::string& plot, double height, double width, double vvi) {
    Json line = Json::parse(truthLine(plot, height, width, vvi));
    line["stereo_view"] = Json::parse(truthLine(plot, height, width - 0.04, vvi));
    line["stereo_view"].erase("plot");
    return line.dump();
  };
  writeLines(truth, {meshLine("A", 1.00, 0.50, 0.40), meshLine("B", 2.00, 0.80, 0.50),
                     meshLine("C", 1.50, 0.60, 0.20)});
  const auto seen = runFieldrig(
      {"evaluate", results_dir.string(), "--truth", truth.string(), "--summary-only"}, dir.path());
  ASSERT_EQ(seen.exit_code, 0) << seen.err;
  EXPECT_NEAR(Json::parse(seen.out_lines.back())["summary"]["width_m"]["bias"].get<double>(), -0.01,
              1e-9);
  const auto stereo = runFieldrig({"evaluate", results_dir.string(), "--truth", truth.string(),
                                   "--truth-view", "stereo", "--summary-only"},
                                  dir.path());
  ASSERT_EQ(stereo.exit_code, 0) << stereo.err;
  const Json width = Json::parse(stereo.out_lines.back())["summary"]["width_m"];
  EXPECT_NEAR(width["bias"].get<double>(), 0.03, 1e-9);
  EXPECT_NEAR(width["max_abs"].get<double>(), 0.06, 1e-9);
  EXPECT_EQ(width["worst_plot"], "B");

  // A view block whose traits failed is not scored against its zeros: B's stereo view has no
  // plants, so only A is scored (width error 0) and B is named.
  Json b = Json::parse(meshLine("B", 2.00, 0.80, 0.50));
  b["stereo_view"] = {{"status", "no_plants"}, {"height_m", 0.0}, {"width_m", 0.0}, {"vvi", 0.0}};
  writeLines(truth, {meshLine("A", 1.00, 0.50, 0.40), b.dump(), meshLine("C", 1.50, 0.60, 0.20)});
  const auto failed_view = runFieldrig({"evaluate", results_dir.string(), "--truth", truth.string(),
                                        "--truth-view", "stereo", "--summary-only"},
                                       dir.path());
  ASSERT_EQ(failed_view.exit_code, 0) << failed_view.err;
  const Json failed_summary = Json::parse(failed_view.out_lines.back())["summary"];
  EXPECT_EQ(failed_summary["truth_not_ok"], Json::array({"B"}));
  EXPECT_EQ(failed_summary["width_m"]["plots"], 1);
  EXPECT_NEAR(failed_summary["width_m"]["max_abs"].get<double>(), 0.0, 1e-9);

  // A truth without that block (the fixture's plain lines, or a field simulated before the
  // block existed) is refused with the line, not scored against the seen view.
  writeLines(truth, {truthLine("A", 1.00, 0.50, 0.40)});
  const auto old_truth = runFieldrig(
      {"evaluate", results_dir.string(), "--truth", truth.string(), "--truth-view", "stereo"},
      dir.path());
  EXPECT_EQ(old_truth.exit_code, 2);
  EXPECT_NE(old_truth.err.find("truth.jsonl:1: plot A: no \"stereo_view\" object"),
            std::string::npos)
      << old_truth.err;
  EXPECT_TRUE(old_truth.out_lines.empty());
  const auto unknown = runFieldrig(
      {"evaluate", results_dir.string(), "--truth", truth.string(), "--truth-view", "left"},
      dir.path());
  EXPECT_EQ(unknown.exit_code, 2) << "an unknown view is a usage error";
}

TEST_F(EvaluateCli, BadFilesAreNamedWithTheLineAndField) {
  struct Case {
    std::string what;
    std::vector<std::string> truth_lines;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"not JSON", {truthLine("A", 1, 0.5, 0.4), "{oops"}, "truth.jsonl:2: not a JSON line"},
      {"no id", {Json{{"height_m", 1.0}}.dump()}, "truth.jsonl:1: no \"plot\""},
      {"a trait as text",
       {Json{{"plot", "A"}, {"height_m", "tall"}}.dump()},
       "truth.jsonl:1: plot A: \"height_m\" is not a finite number"},
      {"a plot twice",
       {truthLine("A", 1, 0.5, 0.4), truthLine("A", 1, 0.5, 0.4)},
       "truth.jsonl:2: plot A appears twice"},
      {"empty", {}, "truth.jsonl: no plots"},
      {"no traits at all",
       {Json{{"plot", "A"}, {"set", 0}}.dump()},
       "truth.jsonl:1: plot A: status ok but none of height_m, width_m, vvi, vai is a number"},
      {"traits not an object",
       {Json{{"plot", "A"}, {"traits", "oops"}}.dump()},
       "truth.jsonl:1: plot A: \"traits\" is not an object"},
      {"status not a string",
       {Json{{"plot", "A"}, {"status", 1}, {"height_m", 1.0}}.dump()},
       "truth.jsonl:1: plot A: \"status\" is not a string"},
  };
  for (const Case& c : cases) {
    writeLines(truth, c.truth_lines);
    const auto run =
        runFieldrig({"evaluate", results_dir.string(), "--truth", truth.string()}, dir.path());
    EXPECT_EQ(run.exit_code, 2) << c.what;
    EXPECT_NE(run.err.find(c.expected), std::string::npos) << c.what << ": " << run.err;
    EXPECT_TRUE(run.out_lines.empty()) << c.what << ": nothing half-printed";
  }
  const auto folder =
      runFieldrig({"evaluate", dir.path().string(), "--truth", truth.string()}, dir.path());
  EXPECT_EQ(folder.exit_code, 2);
  EXPECT_NE(folder.err.find("a folder without plots.jsonl"), std::string::npos) << folder.err;
}

}  // namespace
}  // namespace fieldrig
