#include "fieldrig/sim/trait_evaluation.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>

namespace fieldrig::sim {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// `where` ("truth.jsonl:3") + what is wrong with one plot object.
core::Result<PlotTraitValues> plotFromJson(const Json& object, const std::string& where,
                                           const std::string& block) {
  if (!object.is_object())
    return core::Error{where + ": a plot must be a JSON object"};
  PlotTraitValues plot;
  for (const char* key : {"plot", "location"}) {
    const auto id = object.find(key);
    if (id != object.end() && id->is_string() && !id->get<std::string>().empty()) {
      plot.plot = id->get<std::string>();
      break;
    }
  }
  if (plot.plot.empty())
    return core::Error{where + ": no \"plot\" (or \"location\") id"};
  // Results nest the traits under "traits"; truth lines hold them at the top, and other
  // definitions of the truth in their own object.
  const std::string nested_name = block.empty() ? "traits" : block;
  const auto nested = object.find(nested_name);
  if (!block.empty() && (nested == object.end() || !nested->is_object()))
    return core::Error{where + ": plot " + plot.plot + ": no \"" + block +
                       "\" object (a truth written before it existed: simulate the field again)"};
  // A "traits" that is there but not an object is damage, not a truth line's flat layout.
  if (nested != object.end() && !nested->is_object())
    return core::Error{where + ": plot " + plot.plot + ": \"" + nested_name +
                       "\" is not an object"};
  const Json& traits = nested != object.end() ? *nested : object;
  if (const auto status = traits.find("status"); status != traits.end()) {
    if (!status->is_string())
      return core::Error{where + ": plot " + plot.plot + ": \"status\" is not a string"};
    plot.status = status->get<std::string>();
  }
  std::string names;
  for (const ComparedTrait& trait : kComparedTraits) {
    names += (names.empty() ? "" : ", ") + std::string(trait.name);
    const auto value = traits.find(trait.name);
    if (value == traits.end() || value->is_null())
      continue;
    if (!value->is_number() || !std::isfinite(value->get<double>()))
      return core::Error{where + ": plot " + plot.plot + ": \"" + trait.name +
                         "\" is not a finite number"};
    plot.traits[trait.name] = value->get<double>();
  }
  // A plot said to be ok must carry something to compare, or it would count as scored with
  // nothing compared (a failed plot's traits are null by design).
  if (plot.status == "ok" && plot.traits.empty())
    return core::Error{where + ": plot " + plot.plot + ": status ok but none of " + names +
                       " is a number"};
  return plot;
}

// Right-aligned in `width` columns; numbers with `decimals` places.
std::string cell(const std::string& text, int width) {
  std::ostringstream out;
  out << std::setw(width) << text;
  return out.str();
}

std::string cell(double value, int width, int decimals) {
  std::ostringstream out;
  out << std::setw(width) << std::fixed << std::setprecision(decimals) << value;
  return out.str();
}

}  // namespace

core::Result<std::vector<PlotTraitValues>> readPlotTraits(const fs::path& path,
                                                          const std::string& block) {
  std::error_code error;
  fs::path file = path;
  if (fs::is_directory(path, error)) {
    file = path / "plots.jsonl";
    if (!fs::is_regular_file(file, error))
      return core::Error{path.string() +
                         ": a folder without plots.jsonl (give a results folder, "
                         "a JSON-lines file or a JSON file)"};
  }
  std::ifstream in(file, std::ios::binary);
  if (!in)
    return core::Error{file.string() + ": cannot open"};
  std::vector<PlotTraitValues> plots;
  std::set<std::string> seen;
  auto add = [&](const Json& object, const std::string& where) -> core::Result<void> {
    core::Result<PlotTraitValues> plot = plotFromJson(object, where, block);
    if (!plot)
      return plot.error();
    if (!seen.insert(plot->plot).second)
      return core::Error{where + ": plot " + plot->plot + " appears twice"};
    plots.push_back(std::move(*plot));
    return {};
  };
  if (file.extension() == ".json") {
    const Json document = Json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (document.is_discarded())
      return core::Error{file.string() + ": not JSON"};
    const Json* list = &document;
    if (document.is_object() && document.contains("plots"))
      list = &document.at("plots");
    if (!list->is_array())
      return core::Error{file.string() + ": expected an array of plots or {\"plots\": [...]}"};
    for (std::size_t i = 0; i < list->size(); ++i) {
      if (core::Result<void> added =
              add((*list)[i], file.string() + ": plots[" + std::to_string(i) + "]");
          !added)
        return added.error();
    }
  } else {
    int line_number = 0;
    for (std::string line; std::getline(in, line);) {
      ++line_number;
      if (line.find_first_not_of(" \t\r") == std::string::npos)
        continue;
      const std::string where = file.string() + ":" + std::to_string(line_number);
      const Json object = Json::parse(line, nullptr, /*allow_exceptions=*/false);
      if (object.is_discarded())
        return core::Error{where + ": not a JSON line"};
      if (core::Result<void> added = add(object, where); !added)
        return added.error();
    }
  }
  if (plots.empty())
    return core::Error{file.string() + ": no plots"};
  return plots;
}

core::Result<TraitEvaluation> evaluateTraits(const std::vector<PlotTraitValues>& results,
                                             const std::vector<PlotTraitValues>& truth) {
  std::map<std::string, const PlotTraitValues*> by_id;
  for (const PlotTraitValues& plot : results)
    by_id[plot.plot] = &plot;
  std::set<std::string> truth_ids;
  for (const PlotTraitValues& plot : truth)
    truth_ids.insert(plot.plot);
  for (const PlotTraitValues& plot : results) {
    if (!truth_ids.count(plot.plot))
      return core::Error{"results plot " + plot.plot + " has no truth (truth plots start " +
                         truth.front().plot + "): results and truth are of different fields"};
  }

  TraitEvaluation evaluation;
  std::map<std::string, std::vector<std::pair<double, std::string>>> errors;
  for (const PlotTraitValues& true_plot : truth) {
    const auto found = by_id.find(true_plot.plot);
    if (found == by_id.end()) {
      evaluation.missing_in_results.push_back(true_plot.plot);
      continue;
    }
    // A truth whose own traits failed (a view block with too little plant in it) has no values
    // to score against: its zeros would read as errors of the pipeline.
    if (true_plot.status != "ok") {
      evaluation.truth_not_ok.push_back(true_plot.plot);
      continue;
    }
    const PlotTraitValues& measured = *found->second;
    PlotComparison comparison{measured.plot, measured.status, {}};
    if (measured.status != "ok")
      evaluation.not_ok.push_back(measured.plot);
    for (const ComparedTrait& trait : kComparedTraits) {
      const auto m = measured.traits.find(trait.name);
      const auto t = true_plot.traits.find(trait.name);
      if (m == measured.traits.end() || t == true_plot.traits.end())
        continue;
      if (trait.relative && t->second == 0)
        continue;  // no relative error against a zero truth
      const double error =
          trait.relative ? (m->second - t->second) / t->second : m->second - t->second;
      comparison.values[trait.name] = {m->second, t->second, error};
      if (measured.status == "ok")
        errors[trait.name].emplace_back(error, measured.plot);
    }
    evaluation.plots.push_back(std::move(comparison));
  }
  if (evaluation.plots.empty()) {
    if (!evaluation.truth_not_ok.empty())
      return core::Error{"no truth plot has status ok (" + evaluation.truth_not_ok.front() +
                         " and " + std::to_string(evaluation.truth_not_ok.size() - 1) +
                         " more): nothing to score against"};
    return core::Error{"results and truth share no plot id"};
  }
  for (const auto& [trait, list] : errors) {
    TraitSummary summary;
    summary.plots = static_cast<int>(list.size());
    for (const auto& [error, plot] : list) {
      summary.mean_abs_error += std::abs(error);
      summary.bias += error;
      if (std::abs(error) >= summary.max_abs_error) {
        summary.max_abs_error = std::abs(error);
        summary.worst_plot = plot;
      }
    }
    summary.mean_abs_error /= summary.plots;
    summary.bias /= summary.plots;
    evaluation.summary[trait] = summary;
  }
  return evaluation;
}

nlohmann::ordered_json evaluationJson(const TraitEvaluation& evaluation) {
  nlohmann::ordered_json out;
  out["plots"] = evaluation.plots.size();
  out["scored"] = evaluation.plots.size() - evaluation.not_ok.size();
  out["not_ok"] = evaluation.not_ok;
  out["truth_not_ok"] = evaluation.truth_not_ok;
  out["missing_in_results"] = evaluation.missing_in_results;
  for (const ComparedTrait& trait : kComparedTraits) {
    const auto found = evaluation.summary.find(trait.name);
    if (found == evaluation.summary.end())
      continue;
    const TraitSummary& s = found->second;
    out[trait.name] = {{"unit", trait.relative ? "fraction of truth" : "m"},
                       {"plots", s.plots},
                       {"mean_abs", s.mean_abs_error},
                       {"max_abs", s.max_abs_error},
                       {"bias", s.bias},
                       {"worst_plot", s.worst_plot}};
  }
  return out;
}

std::string evaluationTable(const TraitEvaluation& evaluation) {
  std::ostringstream table;
  table << std::left << std::setw(12) << "plot" << std::setw(8) << "status" << std::right;
  for (const ComparedTrait& trait : kComparedTraits)
    table << cell(trait.name, 9) << cell("truth", 9)
          << cell(trait.relative ? "err %" : "err cm", 8);
  table << '\n';
  for (const PlotComparison& plot : evaluation.plots) {
    table << std::left << std::setw(12) << plot.plot << std::setw(8) << plot.status << std::right;
    for (const ComparedTrait& trait : kComparedTraits) {
      const auto value = plot.values.find(trait.name);
      if (value == plot.values.end()) {
        table << cell("-", 9) << cell("-", 9) << cell("-", 8);
        continue;
      }
      table << cell(value->second.measured, 9, 3) << cell(value->second.truth, 9, 3)
            << cell(value->second.error * 100.0, 8, 1);
    }
    table << '\n';
  }
  return table.str();
}

}  // namespace fieldrig::sim
