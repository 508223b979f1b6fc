#include "campaigns/scoring/tune_scoring.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "campaigns/scoring/campaign_summary.h"
#include "campaigns/scoring/pod.h"
#include "core/base/json_input.h"
#include "faults/fault.h"

namespace armfault {
namespace tune {

Hit Combine(const RunTable& r, const Setting& k, const TuneSpace& space) {
  Hit best = r.event;
  int best_priority = -1;
  bool pre = r.event.pre;
  const int axes = static_cast<int>(space.axes.size());
  for (int d = 0; d < axes; ++d) {
    const Hit& h = r.hits[d][k[axes]][k[d]];
    pre = pre || h.pre;
    if (h.t == kInf) continue;
    const bool better = space.joint_first ? std::tie(h.t, h.joint, d) < std::tie(best.t, best.joint, best_priority)
                                          : std::tie(h.t, d, h.joint) < std::tie(best.t, best_priority, best.joint);
    if (best.t == kInf || better) {
      best = h;
      best_priority = d;
    }
  }
  best.pre = pre;
  return best;
}

namespace {

// Counts of one setting.
struct Score {
  long detected = 0, isolated = 0, false_alarms = 0, before_onset = 0;
  std::vector<long> family_detected, family_isolated;
};

struct Scorer {
  const std::vector<RunTable>& runs;
  const TuneSpace& space;
  long faulty = 0, healthy = 0;
  std::vector<long> family_runs;
  int part = -1;  // -1: every run; 1: the selection half; 0: the held-out half

  bool Counts(const RunTable& r) const { return part < 0 || r.select == (part == 1); }
  // Fills the run counts of this part.
  void CountRuns(size_t families) {
    faulty = healthy = 0;
    family_runs.assign(families, 0);
    for (const RunTable& r : runs) {
      if (!Counts(r)) continue;
      if (r.family < 0) {
        ++healthy;
      } else {
        ++faulty;
        ++family_runs[r.family];
      }
    }
  }

  Score Evaluate(const Setting& k, std::vector<double>* latencies = nullptr,
                 int latency_family = -2) const {
    Score s;
    s.family_detected.assign(family_runs.size(), 0);
    s.family_isolated.assign(family_runs.size(), 0);
    for (const RunTable& r : runs) {
      if (!Counts(r)) continue;
      const Hit h = Combine(r, k, space);
      const bool detected = h.t != kInf;
      if (r.family < 0) {
        if (detected) ++s.false_alarms;
        continue;
      }
      if (h.pre) ++s.before_onset;
      if (!detected) continue;
      ++s.detected;
      ++s.family_detected[r.family];
      if (h.family == r.family && h.joint == r.joint) {
        ++s.isolated;
        ++s.family_isolated[r.family];
      }
      if (latencies && (latency_family == -1 || latency_family == r.family)) latencies->push_back(h.t - r.onset_s);
    }
    return s;
  }
};

nlohmann::json Rate(long k, long n) {
  if (n == 0) return {{"value", nullptr}, {"low", nullptr}, {"high", nullptr}, {"count", 0}, {"runs", 0}};
  const RateInterval w = Wilson(k, n);
  return {{"value", w.rate}, {"low", w.low}, {"high", w.high}, {"count", k}, {"runs", n}};
}
double Ratio(long k, long n) { return n > 0 ? static_cast<double>(k) / n : 0.0; }

// Median and nearest-rank 95th percentile, as summary.json computes them.
std::pair<nlohmann::json, nlohmann::json> MedianP95(std::vector<double> v) {
  if (v.empty()) return {nullptr, nullptr};
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return {n % 2 == 1 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2, v[(95 * n + 99) / 100 - 1]};
}

// A ROC curve of tuning.json: its points, whether it was swept, and its AUC over the measured
// points only, by trapezoids from the smallest to the largest false-alarm rate reached. Nothing
// is extrapolated to (0, 0) or (1, 1): the rates there were not measured. A curve without a
// threshold of its own, or with fewer than two distinct points, is not swept and has no AUC;
// nor has one whose points all share one false-alarm rate (no range to integrate over).
nlohmann::json RocCurve(const nlohmann::json& parameter, bool own_threshold, const nlohmann::json& points,
                        std::vector<std::pair<double, double>> pts) {
  std::sort(pts.begin(), pts.end());
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  const bool swept = own_threshold && pts.size() >= 2;
  nlohmann::json auc = nullptr, range = nullptr;
  if (swept && pts.back().first > pts.front().first) {
    double area = 0;
    for (size_t i = 1; i < pts.size(); ++i) {
      area += (pts[i].first - pts[i - 1].first) * (pts[i].second + pts[i - 1].second) / 2;
    }
    auc = area;
    range = {pts.front().first, pts.back().first};
  }
  return {{"parameter", parameter}, {"swept", swept}, {"auc", auc}, {"auc_false_alarm_range", range}, {"points", points}};
}

// The number of settings of a space: every axis's values times the significances.
long SettingsOf(const TuneSpace& space) {
  long settings = static_cast<long>(space.SignificanceCount());
  for (const TuneAxis& a : space.axes) settings *= static_cast<long>(a.values.size());
  return settings;
}

// Setting number `s` of the space (mixed radix over the axes, the significance fastest).
Setting SettingAt(const TuneSpace& space, long s) {
  const int axes = static_cast<int>(space.axes.size());
  Setting k(static_cast<size_t>(axes) + 1, 0);
  const long z = static_cast<long>(space.SignificanceCount());
  k[axes] = static_cast<int>(s % z);
  s /= z;
  for (int d = axes - 1; d >= 0; --d) {
    const long size = static_cast<long>(space.axes[d].values.size());
    k[d] = static_cast<int>(s % size);
    s /= size;
  }
  return k;
}

// Ties: fewer false alarms, better isolation, then the larger thresholds (more margin on
// healthy joints the campaign did not cover), each normalised by its axis. True if setting `a`
// is the better tie in the scores `sc`.
bool PreferIn(const TuneSpace& space, const std::vector<Score>& sc, long a, long b) {
  const int axes = static_cast<int>(space.axes.size());
  auto margin = [&](long s) {
    const auto k = SettingAt(space, s);
    double sum = space.significance.empty() ? 0.0 : space.significance[k[axes]] / space.significance.back();
    for (int d = 0; d < axes; ++d) {
      const auto& h = space.axes[d].thresholds;
      sum += h[k[d]] / std::max(1e-12, h.back() + h.front());
    }
    return sum;
  };
  const Score &x = sc[a], &y = sc[b];
  if (x.false_alarms != y.false_alarms) return x.false_alarms < y.false_alarms;
  if (x.isolated != y.isolated) return x.isolated > y.isolated;
  const double ma = margin(a), mb = margin(b);
  if (ma != mb) return ma > mb;
  return a < b;
}

// The operating point: the setting the rule prefers on the scores `chosen` (of the runs
// `choose_on` counts). Throws InputError when no setting meets the false-alarm ceiling.
long ChooseSetting(const TuneSpace& space, const std::vector<Score>& chosen, const Scorer& choose_on,
                   const OperatingRule& rule) {
  auto cdr = [&](const Score& s) { return Ratio(s.detected, choose_on.faulty); };
  auto cfa = [&](const Score& s) { return Ratio(s.false_alarms, choose_on.healthy); };
  long best = -1;
  double best_value = 0;
  for (long s = 0; s < static_cast<long>(chosen.size()); ++s) {
    double value = 0;
    const Score& sc = chosen[s];
    switch (rule.kind) {
      case OperatingRule::Kind::kMaxDetection:
        if (cfa(sc) > rule.false_alarm_ceiling) continue;
        value = cdr(sc);
        break;
      case OperatingRule::Kind::kYouden: value = cdr(sc) - cfa(sc); break;
      case OperatingRule::Kind::kMinCost:
        value = -(rule.miss_cost * (1 - cdr(sc)) + rule.false_alarm_cost * cfa(sc));
        break;
    }
    if (best < 0 || value > best_value || (value == best_value && PreferIn(space, chosen, s, best))) {
      best = s;
      best_value = value;
    }
  }
  if (best < 0) {
    throw InputError("--false-alarm-ceiling", "",
                     "no setting keeps the false-alarm rate at or below " + std::to_string(rule.false_alarm_ceiling) +
                         "; raise the ceiling or widen the sweep");
  }
  return best;
}

// The setting the runs ran with (every axis and the significance at its default).
Setting AsRunSetting(const TuneSpace& space) {
  const int axes = static_cast<int>(space.axes.size());
  Setting as_run_k(static_cast<size_t>(axes) + 1, 0);
  for (int d = 0; d < axes; ++d) {
    const auto& v = space.axes[d].values;
    as_run_k[d] = static_cast<int>(std::find(v.begin(), v.end(), space.axes[d].default_value) - v.begin());
  }
  if (!space.significance.empty()) {
    as_run_k[axes] = static_cast<int>(std::find(space.significance.begin(), space.significance.end(),
                                                space.default_significance) -
                                      space.significance.begin());
  }
  return as_run_k;
}

nlohmann::json SettingJson(const TuneSpace& space, const Setting& k) {
  const int axes = static_cast<int>(space.axes.size());
  nlohmann::json j = nlohmann::json::object();
  for (int d = 0; d < axes; ++d) j[space.axes[d].name] = space.axes[d].values[k[d]];
  if (!space.significance.empty()) j["significance"] = space.significance[k[axes]];
  return j;
}

// A point of tuning.json (operating, default, chosen_on, held_out): the setting k's rates on
// the runs `scorer` counts, overall and per family.
nlohmann::json PointJson(const TuneSpace& space, const FamilyTable& families, const Setting& k, const Scorer& scorer) {
  std::vector<double> all;
  const Score s = scorer.Evaluate(k, &all, -1);
  nlohmann::json j;
  j["setting"] = SettingJson(space, k);
  j["detection_rate"] = Rate(s.detected, scorer.faulty);
  j["false_alarm_rate"] = Rate(s.false_alarms, scorer.healthy);
  j["alarm_before_onset_rate"] = Rate(s.before_onset, scorer.faulty);
  j["isolation_accuracy"] = Rate(s.isolated, s.detected);
  const auto [median, p95] = MedianP95(all);
  j["latency_median_s"] = median;
  j["latency_p95_s"] = p95;
  nlohmann::json per = nlohmann::json::object();
  for (size_t f = 0; f < families.names.size(); ++f) {
    if (scorer.family_runs[f] == 0) continue;
    std::vector<double> lat;
    scorer.Evaluate(k, &lat, static_cast<int>(f));
    const auto [fm, fp] = MedianP95(lat);
    per[families.names[f]] = {{"detection_rate", Rate(s.family_detected[f], scorer.family_runs[f])},
                              {"isolation_accuracy", Rate(s.family_isolated[f], s.family_detected[f])},
                              {"latency_median_s", fm},
                              {"latency_p95_s", fp}};
  }
  j["per_family"] = per;
  return j;
}

// The report's "parameters": each axis with its default and values, then the significance.
nlohmann::json ParametersJson(const TuneSpace& space) {
  nlohmann::json parameters = nlohmann::json::array();
  for (const TuneAxis& a : space.axes) {
    parameters.push_back({{"name", a.name}, {"default", a.default_value}, {"values", a.values}});
  }
  if (!space.significance.empty()) {
    parameters.push_back({{"name", "significance"}, {"default", space.default_significance}, {"values", space.significance}});
  }
  return parameters;
}

nlohmann::json RuleJson(const OperatingRule& rule) {
  switch (rule.kind) {
    case OperatingRule::Kind::kMaxDetection:
      return {{"name", "max_detection"}, {"false_alarm_ceiling", rule.false_alarm_ceiling}};
    case OperatingRule::Kind::kYouden: return {{"name", "youden"}};
    case OperatingRule::Kind::kMinCost:
      return {{"name", "min_cost"}, {"miss_cost", rule.miss_cost}, {"false_alarm_cost", rule.false_alarm_cost}};
  }
  return nullptr;
}

// `extra` then, for a point on the edge of the grid (it may lie beyond it), a warning to widen
// the sweep.
nlohmann::json EdgeWarnings(const TuneSpace& space, const Setting& op, const std::vector<std::string>& extra) {
  const int axes = static_cast<int>(space.axes.size());
  nlohmann::json warnings = nlohmann::json::array();
  for (const std::string& w : extra) warnings.push_back(w);
  for (int d = 0; d < axes; ++d) {
    const auto& v = space.axes[d].values;
    if (v.size() > 1 && (op[d] == 0 || op[d] + 1 == static_cast<int>(v.size()))) {
      warnings.push_back(space.axes[d].name + " = " + FormatNumber(v[op[d]]) +
                         " is at the edge of the swept range [" + FormatNumber(v.front()) + ", " + FormatNumber(v.back()) +
                         "]: widen the sweep to see beyond it");
    }
  }
  if (space.significance.size() > 1 && (op[axes] == 0 || op[axes] + 1 == static_cast<int>(space.significance.size()))) {
    warnings.push_back("significance = " + FormatNumber(space.significance[op[axes]]) +
                       " is at the edge of the swept range [" + FormatNumber(space.significance.front()) + ", " +
                       FormatNumber(space.significance.back()) + "]: widen the sweep to see beyond it");
  }
  return warnings;
}

// The ROC frontier of every setting's scores: per false-alarm count, the best setting; kept
// where detection rises.
std::vector<long> RocFrontier(const TuneSpace& space, const std::vector<Score>& scores) {
  std::map<long, long> by_fa;
  for (long s = 0; s < static_cast<long>(scores.size()); ++s) {
    auto it = by_fa.find(scores[s].false_alarms);
    if (it == by_fa.end() || scores[s].detected > scores[it->second].detected ||
        (scores[s].detected == scores[it->second].detected && PreferIn(space, scores, s, it->second))) {
      by_fa[scores[s].false_alarms] = s;
    }
  }
  std::vector<long> frontier;
  for (const auto& [count, s] : by_fa) {
    if (frontier.empty() || scores[s].detected > scores[frontier.back()].detected) frontier.push_back(s);
  }
  return frontier;
}

// The report's "roc" (overall along the frontier; per family its own detector's limit swept
// with the others at the operating point, or, without a swept detector, its rates along the
// overall frontier) and "latency" (against each swept family's own threshold).
void RocAndLatency(const TuneSpace& space, const FamilyTable& families, const Scorer& scorer,
                   const std::vector<Score>& scores, const Setting& op, nlohmann::json* roc_out,
                   nlohmann::json* latency_out) {
  const int axes = static_cast<int>(space.axes.size());
  auto dr = [&](const Score& s) { return Ratio(s.detected, scorer.faulty); };
  auto fa = [&](const Score& s) { return Ratio(s.false_alarms, scorer.healthy); };
  const std::vector<long> frontier = RocFrontier(space, scores);
  nlohmann::json roc;
  {
    nlohmann::json points = nlohmann::json::array();
    std::vector<std::pair<double, double>> pts;
    for (long s : frontier) {
      pts.emplace_back(fa(scores[s]), dr(scores[s]));
      points.push_back({{"false_alarm_rate", fa(scores[s])}, {"detection_rate", dr(scores[s])}, {"setting", SettingJson(space, SettingAt(space, s))}});
    }
    roc["overall"] = RocCurve(nullptr, true, points, pts);
  }
  // Per family: its own detector's limit swept with the others at the operating point;
  // families without a swept detector: their rates along the overall frontier.
  nlohmann::json latency = nlohmann::json::object();
  for (size_t f = 0; f < families.names.size(); ++f) {
    if (scorer.family_runs[f] == 0) continue;
    const std::string& name = families.names[f];
    int own = -1;
    for (int d = axes - 1; d >= 0; --d) {
      if (name == space.axes[d].family) own = d;
    }
    nlohmann::json points = nlohmann::json::array(), lat_points = nlohmann::json::array();
    std::vector<std::pair<double, double>> pts;
    if (own >= 0) {
      Setting k = op;
      for (size_t i = 0; i < space.axes[own].values.size(); ++i) {
        k[own] = static_cast<int>(i);
        std::vector<double> lat;
        const Score s = scorer.Evaluate(k, &lat, static_cast<int>(f));
        const double worn = space.axes[own].values[i];
        const double x = fa(s), y = Ratio(s.family_detected[f], scorer.family_runs[f]);
        points.push_back({{"threshold", worn}, {"false_alarm_rate", x}, {"detection_rate", y}});
        pts.emplace_back(x, y);
        const auto [m, p] = MedianP95(lat);
        lat_points.push_back({{"threshold", worn}, {"median_s", m}, {"p95_s", p}, {"detected", s.family_detected[f]},
                              {"detection_rate", y}});
      }
      latency[name] = {{"parameter", space.axes[own].name}, {"points", lat_points}};
    } else {
      for (long s : frontier) {
        const double x = fa(scores[s]), y = Ratio(scores[s].family_detected[f], scorer.family_runs[f]);
        points.push_back({{"false_alarm_rate", x}, {"detection_rate", y}});
        pts.emplace_back(x, y);
      }
    }
    // A family without a threshold of its own (tick-level detectors) is not swept: its points
    // only show where the overall frontier leaves it.
    roc[name] = RocCurve(own >= 0 ? nlohmann::json(space.axes[own].name) : nlohmann::json(nullptr),
                         own >= 0, points, pts);
  }
  *roc_out = std::move(roc);
  *latency_out = std::move(latency);
}

// The report's "detection_probability": per family, its detection against magnitude (or the
// named category) at the operating point, with the PoD fit (campaigns/scoring/pod.h).
nlohmann::json DetectionProbability(const TuneSpace& space, const std::vector<RunTable>& runs,
                                    const FamilyTable& families, const Scorer& scorer, const Setting& op) {
  nlohmann::json pod = nlohmann::json::object();
  for (size_t f = 0; f < families.names.size(); ++f) {
    if (scorer.family_runs[f] == 0) continue;
    std::map<std::string, std::pair<long, long>> by_category;
    std::map<double, std::pair<long, long>> by_magnitude;
    std::vector<double> severities;
    std::vector<bool> hits;
    std::string key;
    for (const RunTable& r : runs) {
      if (r.family != static_cast<int>(f)) continue;
      const bool hit = Combine(r, op, space).t != kInf;
      if (!r.magnitude_key.empty()) {
        key = r.magnitude_key;
        auto& c = by_magnitude[r.magnitude];
        ++c.first;
        c.second += hit;
        const double s = FaultSeverity(r.magnitude_key, r.magnitude);
        if (s > 0) {
          severities.push_back(s);
          hits.push_back(hit);
        }
      } else {
        auto& c = by_category[r.category];
        ++c.first;
        c.second += hit;
      }
    }
    nlohmann::json points = nlohmann::json::array();
    auto point = [](const nlohmann::json& magnitude, long runs, long detected) {
      const RateInterval w = Wilson(detected, runs);
      return nlohmann::json{{"magnitude", magnitude}, {"runs", runs}, {"detected", detected},
                            {"rate", w.rate}, {"low", w.low}, {"high", w.high}};
    };
    nlohmann::json fit = nullptr;
    if (!key.empty()) {
      for (const auto& [m, c] : by_magnitude) {
        nlohmann::json p = point(m, c.first, c.second);
        p["severity"] = FaultSeverity(key, m);
        points.push_back(p);
      }
      std::sort(points.begin(), points.end(),
                [](const nlohmann::json& a, const nlohmann::json& b) { return a["severity"].get<double>() < b["severity"].get<double>(); });
      fit = PodFitJson(key, severities, hits);
    } else {
      for (const auto& [category, c] : by_category) points.push_back(point(category, c.first, c.second));
      key = runs.empty() ? "" : "category";
    }
    pod[families.names[f]] = {{"magnitude_key", key}, {"points", points}, {"fit", fit}};
  }
  return pod;
}

}  // namespace

Hit DetectorHit(const DecisionStats& s, Detector d, double threshold, double significance, FamilyTable* families) {
  Hit out;
  for (const DecisionStats::Trace& t : s.traces) {
    if (t.detector != d) continue;
    if (AlarmedBefore(t, threshold, significance)) out.pre = true;
    const DecisionStats::Rise* it = FirstAlarm(t, threshold, significance);
    if (!it) continue;
    if (out.t == kInf || std::tie(it->t_s, t.joint) < std::tie(out.t, out.joint)) {
      out.t = it->t_s;
      out.joint = t.joint;
      out.family = families->Id(it->family.empty() ? Detectors()[static_cast<int>(d)].family : it->family);
    }
  }
  return out;
}

Hit EventHit(const DecisionStats& s, FamilyTable* families) {
  Hit out;
  for (const DecisionStats::Event& e : s.events) {
    if (e.t_s < s.onset_s) out.pre = true;
    if (s.first_tick_s < 0) continue;
    const double t = std::max(e.t_s, s.first_tick_s);
    if (out.t == kInf || std::tie(t, e.joint) < std::tie(out.t, out.joint)) {
      out.t = t;
      out.joint = e.joint;
      out.family = families->Id(e.family);
    }
  }
  return out;
}

// A run's hits under every setting of a published-statistics space.
void StatisticHits(const ThresholdStats& stats, const TuneSpace& space, FamilyTable* families, RunTable* r) {
  for (size_t s = 0; s < space.axes.size(); ++s) {
    const int family = families->Id(stats.statistics[s].family);
    std::vector<Hit> hits;
    for (double h : space.axes[s].values) {
      Hit out;
      for (const ThresholdStats::Trace& t : stats.traces) {
        if (t.statistic != static_cast<int>(s)) continue;
        if (t.pre_max > h) out.pre = true;
        const ThresholdStats::Rise* it = FirstAlarm(t, h);
        if (!it) continue;
        if (out.t == kInf || std::tie(it->t_s, t.joint) < std::tie(out.t, out.joint)) {
          out.t = it->t_s;
          out.joint = t.joint;
          out.family = family;
        }
      }
      hits.push_back(out);
    }
    r->hits.push_back({std::move(hits)});
  }
}

Scored ScoreRuns(const TuneSpace& space, const std::vector<RunTable>& runs, const FamilyTable& families, long failed,
                 const std::string& campaign_name, const std::string& campaign_hash, const TuneOptions& options,
                 const std::vector<std::string>& extra_warnings) {
  // Every run; the half with even seeds, on which the operating point is chosen; the other
  // half, on which its rates are reported without having chosen it (honest rates).
  Scorer scorer{runs, space, 0, 0, {}, -1}, chooser{runs, space, 0, 0, {}, 1}, held_out{runs, space, 0, 0, {}, 0};
  scorer.CountRuns(families.names.size());
  chooser.CountRuns(families.names.size());
  held_out.CountRuns(families.names.size());
  // Too few runs in a half (a tiny campaign): choose on every run and say so.
  const bool split = chooser.faulty > 0 && held_out.faulty > 0 && chooser.healthy > 0 && held_out.healthy > 0;
  const Scorer& choose_on = split ? chooser : scorer;

  // Score every setting (mixed radix over the axes), in parallel: each setting is independent.
  const long settings = SettingsOf(space);
  std::vector<Score> scores(static_cast<size_t>(settings)), chosen_scores(static_cast<size_t>(settings));
  const int threads = options.threads > 0 ? options.threads : tbb::this_task_arena::max_concurrency();
  tbb::task_arena arena(threads);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<long>(0, settings), [&](const tbb::blocked_range<long>& range) {
      for (long s = range.begin(); s != range.end(); ++s) {
        scores[s] = scorer.Evaluate(SettingAt(space, s));
        chosen_scores[s] = split ? choose_on.Evaluate(SettingAt(space, s)) : scores[s];
      }
    });
  });

  const Setting op = SettingAt(space, ChooseSetting(space, chosen_scores, choose_on, options.rule));

  nlohmann::json report;
  report["armfault_version"] = ARMFAULT_VERSION;
  report["campaign"] = campaign_name;
  report["campaign_hash"] = campaign_hash;
  report["runs"] = {{"faulty", scorer.faulty}, {"healthy", scorer.healthy}, {"failed", failed}};
  report["parameters"] = ParametersJson(space);
  report["settings"] = settings;
  report["rule"] = RuleJson(options.rule);
  report["operating_point"] = PointJson(space, families, op, scorer);
  report["default_point"] = PointJson(space, families, AsRunSetting(space), scorer);
  // Honest rates: the point was chosen on one half of the runs (even seeds) and is scored on
  // the other; the chosen half's own rates show how much choosing flatters them.
  nlohmann::json selection = {{"split", split ? "seed parity: chosen on even seeds, scored on odd seeds"
                                              : "none: a half would have no faulty or no healthy runs"}};
  if (split) {
    selection["chosen_on"] = PointJson(space, families, op, chooser);
    selection["held_out"] = PointJson(space, families, op, held_out);
  }
  report["selection"] = selection;
  // A point on the edge of the grid may lie beyond it: widen the sweep to see.
  report["warnings"] = EdgeWarnings(space, op, extra_warnings);
  nlohmann::json roc, latency;
  RocAndLatency(space, families, scorer, scores, op, &roc, &latency);
  report["roc"] = roc;
  // Detection probability against magnitude at the operating point.
  report["detection_probability"] = DetectionProbability(space, runs, families, scorer, op);
  report["latency"] = latency;

  return {std::move(report), op, settings};
}

}  // namespace tune
}  // namespace armfault
