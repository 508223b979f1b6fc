#include "campaigns/tuning/tuning.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>

#include "campaigns/spec/campaign_spec.h"
#include "campaigns/spec/cases.h"
#include "campaigns/scoring/provenance.h"
#include "campaigns/data/replay.h"
#include "campaigns/running/run_dir.h"
#include "campaigns/scoring/run_record.h"
#include "campaigns/scoring/tune_scoring.h"
#include "core/base/json_input.h"
#include "core/base/distributions.h"
#include "core/monitors/sequential_test.h"
#include "core/monitors/threshold_statistics.h"

namespace armfault {

namespace {

namespace fs = std::filesystem;

// Default axes: from the healthy value (where false alarms start) out to clearly worn.
struct DefaultAxis {
  double from, to;
  int steps;
};
DefaultAxis DefaultAxisOf(Detector d) {
  switch (d) {
    case Detector::kKtFactor: return {0.90, 0.995, 20};
    case Detector::kResistanceFactor: return {1.0, 3.0, 5};
    case Detector::kFrictionFactor: return {1.0, 1.9, 10};
    case Detector::kSensorDrift: return {0.1, 3.1, 6};
  }
  return {0, 0, 1};
}

std::vector<double> Grid(double from, double to, int steps) {
  std::vector<double> v;
  for (int i = 0; i < steps; ++i) {
    // Rounded to 1e-9 so that 0.85 + 3 x 0.01 prints as 0.88.
    const double x = steps == 1 ? from : from + (to - from) * i / (steps - 1);
    v.push_back(std::round(x * 1e9) / 1e9);
  }
  return v;
}

double ParseNumber(const std::string& text, const std::string& what) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v)) {
    throw InputError("--sweep", "", what + ": expected a number, got \"" + text + "\"");
  }
  return v;
}

// FROM:TO:STEPS (inclusive) or one value.
std::vector<double> ParseValues(const std::string& range, const std::string& name) {
  const size_t c1 = range.find(':');
  if (c1 == std::string::npos) return {ParseNumber(range, name)};
  const size_t c2 = range.find(':', c1 + 1);
  if (c2 == std::string::npos) throw InputError("--sweep", "", name + ": expected FROM:TO:STEPS, got \"" + range + "\"");
  const double from = ParseNumber(range.substr(0, c1), name), to = ParseNumber(range.substr(c1 + 1, c2 - c1 - 1), name);
  const double steps = ParseNumber(range.substr(c2 + 1), name);
  if (!(steps >= 1 && steps <= 10000 && steps == std::floor(steps))) {
    throw InputError("--sweep", "", name + ": STEPS must be a whole number from 1 to 10000, got " + range.substr(c2 + 1));
  }
  return Grid(from, to, static_cast<int>(steps));
}

// The comma-separated items of a --sweep spec ("NAME=FROM:TO:STEPS,NAME=VALUE").
std::vector<std::string> SplitSpec(const std::string& spec) {
  std::vector<std::string> items;
  size_t start = 0;
  while (start < spec.size()) {
    size_t comma = spec.find(',', start);
    if (comma == std::string::npos) comma = spec.size();
    items.push_back(spec.substr(start, comma - start));
    start = comma + 1;
  }
  return items;
}

}  // namespace

OperatingRule::Kind OperatingRuleKind(const std::string& name) {
  if (name == "max_detection") return OperatingRule::Kind::kMaxDetection;
  if (name == "youden") return OperatingRule::Kind::kYouden;
  if (name == "min_cost") return OperatingRule::Kind::kMinCost;
  throw InputError("--rule", "", "unknown rule \"" + name + "\" (max_detection, youden, min_cost)");
}

SweepGrid MakeSweepGrid(const MonitorConfig& base, const std::string& spec) {
  SweepGrid grid;
  for (const DetectorInfo& info : Detectors()) {
    const DefaultAxis a = DefaultAxisOf(info.detector);
    grid.axes.push_back({info.detector, Grid(a.from, a.to, a.steps)});
  }
  grid.significance = Grid(1.0, 5.0, 9);
  for (const std::string& item : SplitSpec(spec)) {
    const size_t eq = item.find('=');
    const std::string name = item.substr(0, eq);
    const std::string suffix = ".worn";
    if (name == "significance" && eq != std::string::npos) {
      grid.significance = ParseValues(item.substr(eq + 1), name);
      for (double v : grid.significance) {
        if (!(v > 0 && v <= 100)) throw InputError("--sweep", "", name + ": " + std::to_string(v) + " is not in (0, 100]");
      }
      continue;
    }
    if (eq == std::string::npos || name.size() <= suffix.size() ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) {
      throw InputError("--sweep", "", "expected NAME.worn=FROM:TO:STEPS or NAME.worn=VALUE, got \"" + item + "\"");
    }
    const DetectorInfo* info = nullptr;
    try {
      info = &DetectorByParameter(name.substr(0, name.size() - suffix.size()));
    } catch (const std::out_of_range& e) {
      throw InputError("--sweep", "", e.what());
    }
    const std::vector<double> values = ParseValues(item.substr(eq + 1), name);
    for (double v : values) {
      // The same bounds the monitor config enforces.
      const bool below = info->detector == Detector::kKtFactor;
      if (below ? !(v > 0 && v <= 1) : !(v >= info->healthy)) {
        throw InputError("--sweep", "", name + ": " + std::to_string(v) + " is not a worn limit (" +
                                            (below ? "0 < value <= 1" : "value >= " + std::to_string(info->healthy)) + ")");
      }
    }
    grid.axes[static_cast<int>(info->detector)].worn_values = values;
  }
  // The monitor's own values are always a setting, so the default point is scored the same way.
  auto add_sorted = [](std::vector<double>* v, double x) {
    v->push_back(x);
    std::sort(v->begin(), v->end());
    v->erase(std::unique(v->begin(), v->end()), v->end());
  };
  for (SweepAxis& axis : grid.axes) add_sorted(&axis.worn_values, (base.*LimitsOf(axis.detector)).worn);
  add_sorted(&grid.significance, base.significance);
  return grid;
}

long SettingCount(const SweepGrid& grid) {
  long n = static_cast<long>(grid.significance.size());
  for (const SweepAxis& a : grid.axes) n *= static_cast<long>(a.worn_values.size());
  return n;
}

namespace {

using tune::DetectorHit;
using tune::EventHit;
using tune::FamilyTable;
using tune::RunTable;
using tune::Scored;
using tune::ScoreRuns;
using tune::Setting;
using tune::StatisticHits;
using tune::TuneAxis;
using tune::TuneSpace;

// The levels a published statistic's threshold may be re-scored at (threshold_statistics.h).
std::vector<double> Levels(double threshold, int from, int to, int step) {
  std::vector<double> v;
  for (int k = from; k <= to; k += step) v.push_back(LevelThreshold(threshold, k));
  return v;
}

// The axes of published statistics: by default every 4th level (a factor 4 either way, 19 %
// apart), coarser when there are many statistics; a spec "NAME=FROM:TO:STEPS" or "NAME=VALUE"
// sets thresholds, each moved to the nearest level (levels only: the stored runs re-score those
// exactly). The declared threshold is always a value.
TuneSpace StatisticSpace(const std::vector<StatisticInfo>& statistics, const std::string& spec) {
  TuneSpace space;
  space.joint_first = true;
  const size_t n = statistics.size();
  const int step = n <= 3 ? 4 : n <= 5 ? 8 : 16;
  for (const StatisticInfo& info : statistics) {
    TuneAxis a;
    a.name = info.name;
    a.family = info.family;
    a.default_value = info.threshold;
    a.values = Levels(info.threshold, -kLevelSteps, kLevelSteps, step);
    space.axes.push_back(std::move(a));
  }
  for (const std::string& item : SplitSpec(spec)) {
    const size_t eq = item.find('=');
    const std::string name = item.substr(0, eq);
    auto it = std::find_if(space.axes.begin(), space.axes.end(), [&](const TuneAxis& a) { return a.name == name; });
    if (eq == std::string::npos || it == space.axes.end()) {
      std::string known;
      for (const TuneAxis& a : space.axes) known += (known.empty() ? "" : ", ") + a.name;
      throw InputError("--sweep", "",
                       "expected NAME=FROM:TO:STEPS or NAME=VALUE with NAME a statistic the monitor publishes (" + known +
                           "), got \"" + item + "\"");
    }
    std::vector<double> values;
    for (double v : ParseValues(item.substr(eq + 1), name)) {
      const double h = it->default_value;
      if (!(v > 0)) throw InputError("--sweep", "", name + ": " + FormatNumber(v) + " is not a threshold > 0");
      const double k = std::round(std::log2(v / h) * kLevelsPerOctave);
      if (std::fabs(k) > kLevelSteps) {
        throw InputError("--sweep", "",
                         name + ": " + FormatNumber(v) + " is outside the range the runs stored, " +
                             FormatNumber(LevelThreshold(h, -kLevelSteps)) + " to " +
                             FormatNumber(LevelThreshold(h, kLevelSteps)) + " (a factor 4 either way of the threshold " +
                             FormatNumber(h) + ")");
      }
      values.push_back(LevelThreshold(h, static_cast<int>(k)));
    }
    it->values = values;
  }
  long settings = 1;
  for (TuneAxis& a : space.axes) {
    a.values.push_back(a.default_value);
    std::sort(a.values.begin(), a.values.end());
    a.values.erase(std::unique(a.values.begin(), a.values.end()), a.values.end());
    a.thresholds = a.values;
    settings *= static_cast<long>(a.values.size());
    if (settings > 2'000'000) {
      throw InputError("--sweep", "",
                       "the monitor publishes " + std::to_string(n) +
                           " statistics: the default grid is too large; fix some with NAME=VALUE in --sweep");
    }
  }
  return space;
}

// The power monitor's grid as a space: its detectors' worn limits and the shared significance.
TuneSpace PowerSpace(const SweepGrid& grid, const MonitorConfig& base) {
  TuneSpace space;
  for (const SweepAxis& a : grid.axes) {
    const DetectorInfo& info = Detectors()[static_cast<int>(a.detector)];
    TuneAxis axis;
    axis.name = std::string(info.parameter) + ".worn";
    axis.family = info.family;
    axis.default_value = (base.*LimitsOf(a.detector)).worn;
    axis.values = a.worn_values;
    for (double worn : a.worn_values) axis.thresholds.push_back(ThresholdFor(info, worn));
    space.axes.push_back(std::move(axis));
  }
  space.significance = grid.significance;
  space.default_significance = base.significance;
  return space;
}

// The sequential decision's space (docs/monitor.md, "Sequential decision"): one axis, the arm's
// target false alarms per hour, which sets every CUSUM's threshold; no significance. A spec
// "target_false_alarms_per_hour=FROM:TO:STEPS" or "=VALUE" sets its values (items add up:
// "target_false_alarms_per_hour=1,target_false_alarms_per_hour=10"); the campaign's own target
// is always one.
TuneSpace SequentialSpace(const MonitorConfig& base, const std::string& spec) {
  TuneSpace space;
  TuneAxis a;
  a.name = "target_false_alarms_per_hour";
  a.default_value = base.target_false_alarms_per_hour;
  std::vector<double> given;  // each item adds its values
  for (const std::string& item : SplitSpec(spec)) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos || item.substr(0, eq) != a.name) {
      throw InputError("--sweep", "",
                       "the campaign's monitor decides sequentially: expected target_false_alarms_per_hour=FROM:TO:STEPS or "
                       "target_false_alarms_per_hour=VALUE, got \"" + item + "\"");
    }
    for (double v : ParseValues(item.substr(eq + 1), a.name)) {
      if (!(v > 0)) throw InputError("--sweep", "", a.name + ": " + FormatNumber(v) + " is not a rate > 0 alarms per hour");
      given.push_back(v);
    }
  }
  a.values = given.empty() ? std::vector<double>{0.1, 0.3, 1, 2, 3, 5, 10, 20, 50} : given;
  a.values.push_back(a.default_value);
  std::sort(a.values.begin(), a.values.end());
  a.values.erase(std::unique(a.values.begin(), a.values.end()), a.values.end());
  // A lower target is the larger margin (higher thresholds): ties prefer it.
  for (double v : a.values) a.thresholds.push_back(1.0 / v);
  space.axes.push_back(std::move(a));
  return space;
}

// The first alarm over the swept detectors (Decide()'s order at one tick: the detectors in
// order, each at its lower joint) with every CUSUM at its threshold for `target`.
tune::Hit SequentialHit(const DecisionStats& stats, const MonitorConfig& base, double target, FamilyTable* families) {
  const DetectorThresholds h = SequentialThresholds(base, stats.sequential_tests, target);
  tune::Hit best;
  for (const DetectorInfo& info : Detectors()) {
    const tune::Hit hit = DetectorHit(stats, info.detector, h[static_cast<int>(info.detector)], kSequentialSignificance, families);
    best.pre = best.pre || hit.pre;
    if (hit.t < best.t) {
      const bool pre = best.pre;
      best = hit;
      best.pre = pre;
    }
  }
  return best;
}

bool SameDeclarations(const std::vector<StatisticInfo>& a, const std::vector<StatisticInfo>& b) {
  if (a.size() != b.size()) return false;
  for (size_t k = 0; k < a.size(); ++k) {
    if (a[k].name != b[k].name || a[k].family != b[k].family || a[k].threshold != b[k].threshold ||
        a[k].setting != b[k].setting) {
      return false;
    }
  }
  return true;
}

// A run directory being tuned: its files, its monitor, and what reading its runs builds.
struct TuneDir {
  std::string dir_name;
  fs::path campaign_path, results_path, decisions_path;
  bool power = false;                 // the power-efficiency monitor: its detectors are swept
  bool sequential = false;            // power, "decision": "sequential": its target rate is swept
  std::optional<MonitorConfig> base;  // power: its settings as its runs used them (widened, unless commissioned)
  DetectorThresholds thresholds{};    // power: the thresholds of those settings
  std::string cannot_sweep;           // why a monitor that publishes no statistics is not swept
  // Filled by ReadRunTables: the space (published statistics: from the first run's), the
  // families as they come, each completed run's table of first alarms, the failed runs.
  TuneSpace space;
  std::vector<StatisticInfo> declared;  // published statistics: what the first run declared
  FamilyTable families;
  std::vector<RunTable> runs;
  long failed = 0;
  // Left out of every rate, as summary.json leaves them out: faulty runs whose fault could not
  // act (unless the campaign includes them) and whose onset condition never fired.
  bool include_not_excited = false;
  long not_excited = 0, not_injected = 0;
  long compound = 0;  // compound runs: tune scores single faults only
};

// One completed run's table of first alarms under every setting, from its stored statistics
// (`decision`), which must reproduce its recorded outcome; appended to td->runs. `where`
// ("line N: ") and `separate` (decisions.jsonl exists) are for messages.
void AddRunTable(const RunRecord& rec, const nlohmann::json& decision, bool separate, const std::string& where,
                 const std::string& sweep, TuneDir* td) {
  const std::string decision_file = separate ? td->decisions_path.string() : td->results_path.string();
  if (!td->power && decision.is_null()) throw InputError(td->campaign_path.string(), "/campaign/monitor/type", td->cannot_sweep);
  RunTable r;
  r.select = rec.seed % 2 == 0;
  r.family = rec.family.empty() ? -1 : td->families.Id(rec.family);
  r.joint = rec.joint;
  r.magnitude_key = rec.magnitude_key;
  r.magnitude = rec.magnitude;
  r.category = PodCategory(rec.fault);
  r.onset_s = rec.onset_s;
  // The stored statistics must give the recorded outcome under the thresholds the run used.
  auto reproduces = [&](bool alarm_before_onset, bool detected, double time_s, const std::string& family, int joint) {
    if (detected != rec.detected || alarm_before_onset != rec.alarm_before_onset ||
        (detected && (time_s != *rec.detection_time_s || family != rec.isolated_family || joint != rec.isolated_joint))) {
      throw InputError(td->results_path.string(), "",
                       where + "run " + rec.run_id + ": its decision statistics do not reproduce its result" +
                           (td->power ? "" : " (the monitor's alarms are not the threshold test on the statistics it "
                                         "publishes: docs/monitor-api.md, \"Statistics for tune\")"));
    }
  };
  if (td->power) {
    DecisionStats stats;
    try {
      if (decision.is_null()) {
        throw std::runtime_error(separate ? "run \"" + rec.run_id + "\" has no decision statistics (null)"
                                          : "no decision statistics: " + td->decisions_path.string() +
                                                " does not exist and this line carries no inline \"decision\" (was "
                                                "the campaign run with --summary-only? run it again without)");
      }
      stats = DecisionStatsFromJson(decision);
    } catch (const std::exception& e) {
      throw InputError(decision_file, "", where + e.what());
    }
    if (td->sequential) {
      if (stats.sequential_tests <= 0) {
        throw InputError(decision_file, "", where + "run " + rec.run_id +
                                                ": no sequential tests stored, but the campaign's monitor decides "
                                                "sequentially (results of another monitor version?)");
      }
      const DecisionOutcome check = Decide(stats, SequentialThresholds(*td->base, stats.sequential_tests), kSequentialSignificance);
      reproduces(check.alarm_before_onset, check.detected, check.detection_time_s, check.family, check.joint);
      r.event = EventHit(stats, &td->families);
      r.observed_s = std::max(0.0, stats.last_tick_s - std::max(0.0, stats.first_tick_s));
      auto& hits = r.hits.emplace_back();
      hits.emplace_back();
      for (double target : td->space.axes[0].values) hits.back().push_back(SequentialHit(stats, *td->base, target, &td->families));
      td->runs.push_back(std::move(r));
      return;
    }
    const DecisionOutcome check = Decide(stats, td->thresholds, td->base->significance);
    reproduces(check.alarm_before_onset, check.detected, check.detection_time_s, check.family, check.joint);
    r.event = EventHit(stats, &td->families);
    for (size_t d = 0; d < td->space.axes.size(); ++d) {
      const DetectorInfo& info = Detectors()[d];
      auto& hits = r.hits.emplace_back();
      for (double z : td->space.significance) {
        hits.emplace_back();
        for (double worn : td->space.axes[d].values) {
          hits.back().push_back(DetectorHit(stats, info.detector, ThresholdFor(info, worn), z, &td->families));
        }
      }
    }
  } else {
    ThresholdStats stats;
    try {
      stats = ThresholdStatsFromJson(decision);
      if (td->declared.empty()) {
        td->declared = stats.statistics;
        td->space = StatisticSpace(td->declared, sweep);
      } else if (!SameDeclarations(td->declared, stats.statistics)) {
        throw std::runtime_error("run \"" + rec.run_id + "\" declares other statistics than the first run");
      }
    } catch (const std::exception& e) {
      if (dynamic_cast<const InputError*>(&e)) throw;
      throw InputError(decision_file, "", where + e.what());
    }
    std::vector<double> thresholds;
    for (const StatisticInfo& info : td->declared) thresholds.push_back(info.threshold);
    const ThresholdOutcome check = DecideThresholds(stats, thresholds);
    reproduces(check.alarm_before_onset, check.detected, check.detection_time_s, check.family, check.joint);
    StatisticHits(stats, td->space, &td->families, &r);
  }
  td->runs.push_back(std::move(r));
}

// Reads results.jsonl and decisions.jsonl line for line (without the latter, results.jsonl's
// inline "decision"), each line a case of the campaign (`matcher`), into td.
void ReadRunTables(const CaseMatcher& matcher, const std::string& sweep, TuneDir* td) {
  // Each run's statistics are the same line of decisions.jsonl, of the same run; in an older
  // armfault's directory, without that file, the results line's own "decision".
  const bool separate = fs::exists(td->decisions_path);
  std::ifstream decisions_in;
  if (separate) {
    decisions_in.open(td->decisions_path, std::ios::binary);
    if (!decisions_in) throw InputError(td->decisions_path.string(), "", "cannot read the file");
  }
  std::string decision_line;
  long n = 0;
  JsonLinesOptions lines;
  lines.open_error = "cannot read (run the campaign first)";
  ReadRunRecords(td->results_path, lines, [&](RunRecord&& rec, long line) {
    n = line;
    auto where = [&] { return "line " + std::to_string(n) + ": "; };
    if (const std::string why = matcher.Mismatch(rec); !why.empty()) {
      throw std::runtime_error(why + matcher.NotOf(td->campaign_path.string(), td->dir_name));
    }
    nlohmann::json decision = std::move(rec.decision);
    if (separate) {
      try {
        if (!std::getline(decisions_in, decision_line)) {
          throw std::runtime_error("missing: the file ends after " + std::to_string(n - 1) + " lines, but " +
                                   td->results_path.string() + " has more");
        }
        if (decisions_in.eof()) {
          throw std::runtime_error("cut: the line has no newline (a killed run? finish it with `armfault run ... --resume`)");
        }
        DecisionLine d = DecisionLineFromJson(nlohmann::json::parse(decision_line));
        if (d.case_index != rec.case_index || d.run_id != rec.run_id) {
          throw std::runtime_error("case " + std::to_string(d.case_index) + " \"" + d.run_id + "\", but line " +
                                   std::to_string(n) + " of " + td->results_path.string() + " is case " +
                                   std::to_string(rec.case_index) + " \"" + rec.run_id +
                                   "\": decisions.jsonl does not go with results.jsonl");
        }
        decision = std::move(d.decision);
      } catch (const std::exception& e) {
        throw InputError(td->decisions_path.string(), "", where() + e.what());
      }
    }
    if (!rec.ok) {
      ++td->failed;
      return;
    }
    if (!rec.family.empty() && !rec.injected()) {  // its onset condition never fired: no fault to detect
      ++td->not_injected;
      return;
    }
    if (!rec.family.empty() && !rec.excited()) {
      // Its fault could not act: out of every rate unless the campaign scores such runs.
      ++td->not_excited;
      if (!td->include_not_excited) return;
    }
    if (rec.is_compound()) {  // several faults at once: no family or magnitude to fit
      ++td->compound;
      return;
    }
    AddRunTable(rec, decision, separate, where(), sweep, td);
  });
  if (separate && std::getline(decisions_in, decision_line)) {
    throw InputError(td->decisions_path.string(), "",
                     "line " + std::to_string(n + 1) + ": more lines than the " + std::to_string(n) + " runs of " +
                         td->results_path.string() + ": decisions.jsonl does not go with results.jsonl");
  }
}

// The tuned monitor at the operating point `op`: the power monitor's config with its limits;
// another type's "monitor" value (`monitor_json`, else the campaign's) with each statistic's
// threshold written where it declared it lives (not for a Python monitor passed as a factory).
void SetTunedMonitor(const TuneDir& td, const Setting& op, const nlohmann::json& monitor_json, const CampaignSpec& campaign,
                     bool python_monitor, TuningResult* result) {
  if (td.sequential) {
    result->tuned = *td.base;
    result->tuned.target_false_alarms_per_hour = td.space.axes[0].values[op[0]];
    Validate(result->tuned, "", "<tuned monitor>");
    result->tuned_monitor = MonitorConfigToJson(result->tuned);
  } else if (td.power) {
    result->tuned = *td.base;
    for (size_t d = 0; d < td.space.axes.size(); ++d) {
      StateLimits& l = result->tuned.*LimitsOf(Detectors()[d].detector);
      l.worn = td.space.axes[d].values[op[d]];
      // Keep the defective limit beyond the worn one.
      l.defective =
          Detectors()[d].detector == Detector::kKtFactor ? std::min(l.defective, l.worn) : std::max(l.defective, l.worn);
    }
    result->tuned.significance = td.space.significance[op[td.space.axes.size()]];
    Validate(result->tuned, "", "<tuned monitor>");
    result->tuned_monitor = MonitorConfigToJson(result->tuned);
  } else {
    result->tuned_monitor = monitor_json.is_null() ? campaign.monitor.ToJson() : monitor_json;
    for (size_t s = 0; s < td.declared.size(); ++s) {
      if (td.declared[s].setting.empty() || python_monitor) continue;
      const nlohmann::json::json_pointer at("/settings" + td.declared[s].setting);
      result->tuned_monitor[at] = td.space.axes[s].values[op[s]];
    }
  }
}

// The report's "rate_calibration" (sequential decision): per swept target, the healthy runs'
// false alarms over their hours to the first alarm (each run counts until it alarms), the rate
// measured with its exact 95 % interval, the count the target predicts over those hours (its
// central 95 % interval) and whether the count seen lies inside it; the faulty runs' detection
// and median latency at that target, overall and per family.
nlohmann::json RateCalibration(const TuneDir& td) {
  nlohmann::json points = nlohmann::json::array();
  const TuneAxis& axis = td.space.axes[0];
  for (size_t v = 0; v < axis.values.size(); ++v) {
    const tune::Setting k = {static_cast<int>(v), 0};
    long alarms = 0, faulty = 0, detected = 0;
    double exposure_s = 0;
    std::vector<double> latencies;
    std::map<std::string, std::vector<double>> family_latencies;
    std::map<std::string, std::pair<long, long>> family_counts;
    for (const RunTable& r : td.runs) {
      const tune::Hit h = tune::Combine(r, k, td.space);
      if (r.family < 0) {
          const bool alarm = h.t != tune::kInf;
        alarms += alarm ? 1 : 0;
        exposure_s += alarm ? std::min(h.t, r.observed_s) : r.observed_s;
        continue;
      }
      ++faulty;
      auto& counts = family_counts[td.families.names[r.family]];
      ++counts.first;
      if (h.t == tune::kInf) continue;  // detected as summary.json and the scores count it (an earlier alarm too)
      ++detected;
      ++counts.second;
      latencies.push_back(h.t - r.onset_s);
      family_latencies[td.families.names[r.family]].push_back(h.t - r.onset_s);
    }
    auto median = [](std::vector<double> x) -> nlohmann::json {
      if (x.empty()) return nullptr;
      std::sort(x.begin(), x.end());
      const size_t n = x.size();
      return n % 2 ? x[n / 2] : 0.5 * (x[n / 2 - 1] + x[n / 2]);
    };
    const double target = axis.values[v], hours = exposure_s / 3600.0;
    nlohmann::json p = {{"target_per_hour", target}, {"healthy_hours", hours}, {"false_alarms", alarms}};
    if (hours > 0) {
      const auto [lo, hi] = PoissonCountInterval(target * hours, 0.95);
      p["measured_per_hour"] = alarms / hours;
      p["measured_interval_per_hour"] = {PoissonLowerBound(alarms, 0.975) / hours, PoissonUpperBound(alarms, 0.975) / hours};
      p["target_count_interval"] = {lo, hi};
      p["consistent"] = alarms >= lo && alarms <= hi;
    } else {
      p["measured_per_hour"] = nullptr;
    }
    p["faulty_runs"] = faulty;
    p["detected"] = detected;
    p["detection_rate"] = faulty > 0 ? nlohmann::json(static_cast<double>(detected) / static_cast<double>(faulty)) : nullptr;
    p["median_latency_s"] = median(latencies);
    nlohmann::json families = nlohmann::json::object();
    for (const auto& [name, c] : family_counts) {
      families[name] = {{"runs", c.first}, {"detected", c.second}, {"median_latency_s", median(family_latencies[name])}};
    }
    p["families"] = families;
    points.push_back(std::move(p));
  }
  return {{"parameter", axis.name}, {"as_run", axis.default_value}, {"points", points}};
}

}  // namespace

TuningResult TuneCampaignDir(const std::string& dir_name, const TuneOptions& options) {
  const fs::path dir(dir_name);
  TuneDir td;
  td.dir_name = dir_name;
  td.campaign_path = dir / "campaign.json";
  td.results_path = dir / "results.jsonl";
  td.decisions_path = dir / "decisions.jsonl";
  const fs::path& campaign_path = td.campaign_path;
  // The spec alone: no trajectory file is read and no monitor built (a Python monitor's, say,
  // which only the Python package can build); tune needs the cases and the stored statistics.
  const nlohmann::json campaign_file = ReadCampaignFileJson(dir);
  const CampaignSpec campaign = CampaignSpecFromJson(campaign_file["campaign"], campaign_path.string(), dir.string());
  // Verdicts scored by `armfault score` are decisions already made: no statistic behind them
  // is stored, and their thresholds live in the detector that wrote them.
  if (campaign.monitor.type == "verdicts") {
    throw InputError(campaign_path.string(), "/campaign/monitor/type",
                     "a directory of armfault score (verdicts of " + campaign.monitor.settings.value("file", "") +
                         "): verdicts cannot be re-thresholded; tune the detector that wrote them");
  }
  const nlohmann::json monitor_json = campaign_file["campaign"].value("monitor", nlohmann::json());
  // A Python monitor passed to run_campaign (its "factory") has no settings to write into; one
  // named by its class has, as a plugin has (its "settings", the instance's self.settings).
  const bool python_monitor = campaign.monitor.type == "python" && !campaign.monitor.settings.contains("class");
  const std::string monitor_type = campaign.monitor.type;
  // Nothing of another campaign is tuned on: summary.json, when there, must be of this
  // campaign.json, and every line of results.jsonl one of its cases (same run_id and seed).
  const std::string campaign_hash = CampaignHash(campaign_file["campaign"]);
  if (const fs::path summary_path = dir / "summary.json"; fs::exists(summary_path)) {
    RequireOneCampaign({{campaign_path.string(), campaign_hash, ""},
                        {summary_path.string(), ClaimedCampaignHash(ReadJsonFile(summary_path.string()), summary_path.string()),
                         "run the campaign into " + dir_name + " again (or merge its shards there), or remove the stale summary.json"}});
  }
  // A replay of an import: its records are the import's runs, not the stand-in campaign's cases.
  const CaseMatcher matcher(campaign, ReplayedImportRuns(dir_name));
  // Only a monitor that publishes the statistics behind its alarms can be re-scored: the
  // power-efficiency monitor (DecisionStats), or any type whose runs stored published statistics
  // (ThresholdStats). Another is scored at its own operating point.
  td.power = !python_monitor && campaign.monitor.type == "power_efficiency";
  td.cannot_sweep = "monitor type \"" + monitor_type +
                    "\" publishes no statistics tune can re-score: its runs are scored at its own "
                    "operating point (see summary.json); a monitor that declares statistics "
                    "(docs/monitor-api.md, \"Statistics for tune\") can be swept";
  // The power-efficiency monitor's settings as its runs used them (widened, unless commissioned).
  if (td.power) {
    td.base = PowerEfficiencyConfig(MonitorConfigFromJson(campaign.monitor.settings, "/monitor", campaign.source),
                                    MonitorContextOf(campaign));
    td.sequential = td.base->decision == kSequentialDecision;
    td.space = td.sequential ? SequentialSpace(*td.base, options.sweep)
                             : PowerSpace(MakeSweepGrid(*td.base, options.sweep), *td.base);
    td.thresholds = ThresholdsOf(*td.base);
  }

  // Load the runs: per run, the first alarm of each axis at each of its values.
  td.include_not_excited = campaign.include_not_excited;
  if (td.power) {
    for (const DetectorInfo& d : Detectors()) td.families.Id(d.family);
  }
  ReadRunTables(matcher, options.sweep, &td);

  if (td.runs.empty()) throw InputError(td.results_path.string(), "", "no completed runs to tune on");

  // The tuned monitor: the power monitor's config with the operating point's limits; another
  // type's "monitor" value with each statistic's threshold written where it declared it lives.
  std::vector<std::string> warnings;
  if (!td.power) {
    for (const StatisticInfo& info : td.declared) {
      if (info.setting.empty() || python_monitor) {
        warnings.push_back("statistic " + info.name +
                           " names no setting that holds its threshold: set it in the monitor yourself (tuned-monitor.json "
                           "holds the monitor as it ran)");
      }
    }
  }
  Scored scored = ScoreRuns(td.space, td.runs, td.families, td.failed, campaign.name, campaign_hash, options, warnings);
  const Setting& op = scored.op;

  TuningResult result;
  SetTunedMonitor(td, op, monitor_json, campaign, python_monitor, &result);
  result.report = std::move(scored.report);
  if (td.sequential) result.report["rate_calibration"] = RateCalibration(td);
  // What was left out of every rate, as summary.json counts it.
  result.report["runs"]["not_excited"] = td.not_excited;
  result.report["runs"]["not_excited_included"] = td.include_not_excited;
  if (td.not_injected > 0) result.report["runs"]["not_injected"] = td.not_injected;
  if (td.compound > 0) result.report["runs"]["compound"] = td.compound;
  result.compound = td.compound;
  result.not_excited = td.include_not_excited ? 0 : td.not_excited;
  result.not_injected = td.not_injected;
  result.settings = scored.settings;
  result.runs = static_cast<long>(td.runs.size());
  return result;
}

}  // namespace armfault
