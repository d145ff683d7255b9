// `fieldrig evaluate RESULTS --truth TRUTH`: a session's plot traits against the truth of the
// synthetic field it was rendered from — a per-plot table, then one JSON summary line.
#include <iostream>

#include "commands/command_helpers.h"
#include "fieldrig/sim/trait_evaluation.h"

namespace fieldrig::tools {
namespace {

struct EvaluateArgs {
  std::string results;
  std::string truth;
  std::string truth_view = "seen";
  bool summary_only = false;
};

int runEvaluate(const EvaluateArgs& args) {
  constexpr const char* kWho = "fieldrig evaluate: ";
  const auto results = sim::readPlotTraits(args.results);
  if (!results)
    return fail(kWho, results.error().message);
  const std::string block = args.truth_view == "stereo" ? "stereo_view"
                            : args.truth_view == "full" ? "full"
                                                        : "";
  const auto truth = sim::readPlotTraits(args.truth, block);
  if (!truth)
    return fail(kWho, truth.error().message);
  const auto evaluation = sim::evaluateTraits(*results, *truth);
  if (!evaluation)
    return fail(kWho, args.results + " against " + args.truth + ": " + evaluation.error().message);
  if (!args.summary_only)
    std::cout << sim::evaluationTable(*evaluation);
  return printJsonLine({{"summary", sim::evaluationJson(*evaluation)}});
}

}  // namespace

void registerEvaluateCommand(CLI::App& app, int& exit_code) {
  const auto [evaluate, args] = addSubcommand(
      app, "evaluate",
      "Plot traits of a results folder against a synthetic field's truth: a per-plot table, then "
      "one JSON summary (per trait mean, max and bias of the error)",
      exit_code, runEvaluate);
  evaluate
      ->add_option("results", args->results,
                   "Results folder (its plots.jsonl) or a plots JSON-lines file")
      ->required();
  evaluate
      ->add_option("--truth", args->truth,
                   "The field's truth: truth.jsonl of `fieldrig simulate`, or a JSON file")
      ->required();
  evaluate
      ->add_option("--truth-view", args->truth_view,
                   "Which plant surfaces a mesh truth's traits are taken on: seen (by some camera; "
                   "the default), stereo (by both cameras of some head: what stereo can place) or "
                   "full (all of the plot's plants in the imaged stretch of row, seen or not)")
      ->check(CLI::IsMember({"seen", "stereo", "full"}));
  evaluate->add_flag("--summary-only", args->summary_only, "Print only the JSON summary line");
}

}  // namespace fieldrig::tools
