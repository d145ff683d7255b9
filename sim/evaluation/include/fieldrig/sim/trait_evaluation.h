// Plot traits measured by the pipeline (a results folder's plots.jsonl) against the truth of a
// synthetic field (truth.jsonl of `fieldrig simulate` / `fieldrig sim plots`, or a truth.json
// holding an array or {"plots": [...]}). Plots are matched by id; every trait present on both
// sides is compared: heights and widths as absolute errors in metres, VVI and VAI as errors
// relative to the truth. `fieldrig evaluate` prints this; benches and tests call it directly.
#pragma once

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fieldrig/core/result.h"

namespace fieldrig::sim {

// One plot's traits by name ("height_m", "width_m", "vvi", "vai"), as read from a file.
struct PlotTraitValues {
  std::string plot;
  std::string status = "ok";  // the pipeline's status; truth is always "ok"
  std::map<std::string, double> traits;
};

// The traits compared and how: absolute (metres) or relative to the truth.
struct ComparedTrait {
  const char* name;
  bool relative;
};
inline constexpr ComparedTrait kComparedTraits[] = {
    {"height_m", false}, {"width_m", false}, {"vvi", true}, {"vai", true}};

struct PlotComparison {
  std::string plot;
  std::string status;
  // Per trait present on both sides: measured, truth, error (measured − truth; relative traits
  // divided by the truth).
  struct Value {
    double measured = 0;
    double truth = 0;
    double error = 0;
  };
  std::map<std::string, Value> values;
};

struct TraitSummary {
  int plots = 0;
  double mean_abs_error = 0;
  double max_abs_error = 0;
  double bias = 0;  // mean signed error
  std::string worst_plot;
};

struct TraitEvaluation {
  std::vector<PlotComparison> plots;            // in the truth's order
  std::vector<std::string> missing_in_results;  // truth plots the results do not have
  std::vector<std::string> not_ok;              // results whose status is not "ok" (not scored)
  std::vector<std::string> truth_not_ok;        // truth plots whose status is not "ok" (skipped)
  std::map<std::string, TraitSummary> summary;  // per trait over the scored plots
};

// Reads one side. `path` is a results folder (its plots.jsonl), a JSON-lines file or a JSON file
// (an array, or an object with "plots"). With `block` ("stereo_view", "full": a mesh truth's
// other definitions of what counts) each plot's traits come from that object of the line, and a
// line without it is an error. Errors name the file, the line and the field.
core::Result<std::vector<PlotTraitValues>> readPlotTraits(const std::filesystem::path& path,
                                                          const std::string& block = {});

// Compares `results` with `truth`. An error when they share no plot id, or when the results hold
// a plot the truth does not know (results of another field): the message names both files'
// first unmatched ids.
core::Result<TraitEvaluation> evaluateTraits(const std::vector<PlotTraitValues>& results,
                                             const std::vector<PlotTraitValues>& truth);

// The summary as JSON: per trait mean_abs, max_abs, bias, worst plot (metres or fractions), and
// the lists of plots not scored.
nlohmann::ordered_json evaluationJson(const TraitEvaluation& evaluation);

// A per-plot table for people: one row per plot, heights and widths in cm, VVI and VAI in %.
std::string evaluationTable(const TraitEvaluation& evaluation);

}  // namespace fieldrig::sim
