#include "core/monitors/threshold_statistics.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <tuple>

#include "core/base/json_input.h"

namespace armfault {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string Rounded(double v) { return FormatNumber(std::round(v * 1e4) / 1e4); }
std::string Ms(double t) { return FormatNumber(std::round(t * 1e3) / 1e3); }

}  // namespace

std::string CheckStatistics(const std::vector<StatisticInfo>& statistics) {
  std::set<std::string> names;
  for (size_t s = 0; s < statistics.size(); ++s) {
    const StatisticInfo& info = statistics[s];
    const std::string which = "statistic " + std::to_string(s + 1) + " (\"" + info.name + "\"): ";
    if (info.name.empty()) return "statistic " + std::to_string(s + 1) + ": empty name";
    if (!names.insert(info.name).second) return which + "name declared twice";
    if (info.family.empty()) return which + "names no family (use \"unknown\" for none in particular)";
    if (!(std::isfinite(info.threshold) && info.threshold > 0)) {
      return which + "threshold " + FormatNumber(info.threshold) + " is not a number > 0";
    }
    if (!info.setting.empty() && info.setting[0] != '/') {
      return which + "setting \"" + info.setting + "\" is not a JSON pointer (\"/name\")";
    }
  }
  return "";
}

double LevelThreshold(double threshold, int k) {
  return k == 0 ? threshold : threshold * std::exp2(static_cast<double>(k) / kLevelsPerOctave);
}

nlohmann::json ToJson(const ThresholdStats& s) {
  nlohmann::json statistics = nlohmann::json::array();
  for (const StatisticInfo& i : s.statistics) {
    statistics.push_back({{"name", i.name}, {"family", i.family}, {"threshold", i.threshold}, {"setting", i.setting}});
  }
  nlohmann::json traces = nlohmann::json::array();
  for (const ThresholdStats::Trace& t : s.traces) {
    nlohmann::json rise = nlohmann::json::array();
    // Times as records hold them (microseconds), so re-scoring gives the recorded times.
    for (const ThresholdStats::Rise& r : t.rise) rise.push_back({RoundToMicroseconds(r.t_s), r.value});
    traces.push_back({{"joint", t.joint},
                      {"statistic", t.statistic},
                      {"pre_max", std::isfinite(t.pre_max) ? nlohmann::json(t.pre_max) : nlohmann::json(nullptr)},
                      {"rise", rise}});
  }
  return {{"kind", "threshold_statistics"},
          {"levels", {{"per_octave", kLevelsPerOctave}, {"steps", kLevelSteps}}},
          {"statistics", statistics},
          {"onset_s", s.onset_s},
          {"first_tick_s", s.first_tick_s < 0 ? s.first_tick_s : RoundToMicroseconds(s.first_tick_s)},
          {"traces", traces}};
}

ThresholdStats ThresholdStatsFromJson(const nlohmann::json& j) {
  auto need = [](const nlohmann::json& o, const char* key, const std::string& where) -> const nlohmann::json& {
    if (!o.is_object() || !o.contains(key)) throw std::runtime_error(where + "missing \"" + key + "\"");
    return o.at(key);
  };
  auto number = [&](const nlohmann::json& o, const char* key, const std::string& where) {
    const nlohmann::json& v = need(o, key, where);
    if (!v.is_number()) throw std::runtime_error(where + "\"" + key + "\" is not a number");
    return v.get<double>();
  };
  if (!j.is_object() || j.value("kind", "") != "threshold_statistics") {
    throw std::runtime_error("decision: not threshold statistics (\"kind\": \"threshold_statistics\")");
  }
  const nlohmann::json& levels = need(j, "levels", "decision: ");
  if (levels != nlohmann::json{{"per_octave", kLevelsPerOctave}, {"steps", kLevelSteps}}) {
    throw std::runtime_error("decision: levels " + levels.dump() + " are not this armfault's");
  }
  ThresholdStats s;
  for (const nlohmann::json& i : need(j, "statistics", "decision: ")) {
    StatisticInfo info;
    info.name = need(i, "name", "decision: statistics: ").get<std::string>();
    info.family = need(i, "family", "decision: statistics: ").get<std::string>();
    info.threshold = number(i, "threshold", "decision: statistics: ");
    info.setting = i.value("setting", "");
    s.statistics.push_back(std::move(info));
  }
  if (const std::string why = CheckStatistics(s.statistics); !why.empty()) throw std::runtime_error("decision: " + why);
  s.onset_s = number(j, "onset_s", "decision: ");
  s.first_tick_s = number(j, "first_tick_s", "decision: ");
  for (const nlohmann::json& t : need(j, "traces", "decision: ")) {
    ThresholdStats::Trace trace;
    trace.joint = need(t, "joint", "decision: traces: ").get<int>();
    trace.statistic = need(t, "statistic", "decision: traces: ").get<int>();
    if (trace.statistic < 0 || trace.statistic >= static_cast<int>(s.statistics.size()) || trace.joint < 1) {
      throw std::runtime_error("decision: traces: joint " + std::to_string(trace.joint) + ", statistic " +
                               std::to_string(trace.statistic) + " out of range");
    }
    const nlohmann::json& pre = need(t, "pre_max", "decision: traces: ");
    if (!pre.is_null()) trace.pre_max = pre.get<double>();
    for (const nlohmann::json& r : need(t, "rise", "decision: traces: ")) {
      if (!r.is_array() || r.size() != 2 || !r[0].is_number() || !r[1].is_number()) {
        throw std::runtime_error("decision: traces: rise: expected [t_s, value], got " + r.dump());
      }
      trace.rise.push_back({r[0].get<double>(), r[1].get<double>()});
    }
    s.traces.push_back(std::move(trace));
  }
  return s;
}

ThresholdRecorder::ThresholdRecorder(std::vector<StatisticInfo> statistics, int joints, double onset_s)
    : joints_(joints) {
  stats_.statistics = std::move(statistics);
  stats_.onset_s = onset_s;
  const size_t n = static_cast<size_t>(joints) * stats_.statistics.size();
  trace_index_.assign(n, -1);
  next_level_.assign(n, -kLevelSteps);
}

void ThresholdRecorder::Show(StatisticsObserver* observer) {
  observer_ = observer;
  if (!observer_) return;
  std::vector<PublishedStatistic> published;
  for (const StatisticInfo& info : stats_.statistics) published.push_back({info.name, info.family, info.threshold, false});
  observer_->Declare(published, joints_);
}

void ThresholdRecorder::Record(double t_s, const double* values) {
  if (observer_) observer_->Values(t_s, values);
  const bool after = t_s >= stats_.onset_s;
  if (after && stats_.first_tick_s < 0) stats_.first_tick_s = t_s;
  const int count = static_cast<int>(stats_.statistics.size());
  for (int j = 0; j < joints_; ++j) {
    for (int s = 0; s < count; ++s) {
      const size_t k = static_cast<size_t>(j * count + s);
      const double v = values[k];
      if (std::isnan(v)) continue;
      if (trace_index_[k] < 0) {
        trace_index_[k] = static_cast<int>(stats_.traces.size());
        stats_.traces.push_back({j + 1, s, -kInf, {}});
      }
      ThresholdStats::Trace& trace = stats_.traces[static_cast<size_t>(trace_index_[k])];
      if (!after) {
        trace.pre_max = std::max(trace.pre_max, v);
        continue;
      }
      const double h = stats_.statistics[static_cast<size_t>(s)].threshold;
      int& next = next_level_[k];
      if (next > kLevelSteps || !(v > LevelThreshold(h, next))) continue;
      trace.rise.push_back({t_s, v});
      while (next <= kLevelSteps && v > LevelThreshold(h, next)) ++next;
    }
  }
}

const ThresholdStats::Rise* FirstAlarm(const ThresholdStats::Trace& trace, double threshold) {
  for (const ThresholdStats::Rise& r : trace.rise) {
    if (r.value > threshold) return &r;
  }
  return nullptr;
}

ThresholdOutcome DecideThresholds(const ThresholdStats& stats, const std::vector<double>& thresholds) {
  ThresholdOutcome out;
  int best_statistic = 0;
  for (const ThresholdStats::Trace& t : stats.traces) {
    const double h = thresholds[static_cast<size_t>(t.statistic)];
    if (t.pre_max > h) out.alarm_before_onset = true;
    const ThresholdStats::Rise* r = FirstAlarm(t, h);
    if (!r) continue;
    if (!out.detected ||
        std::tie(r->t_s, t.joint, t.statistic) < std::tie(out.detection_time_s, out.joint, best_statistic)) {
      out.detected = true;
      out.detection_time_s = r->t_s;
      out.joint = t.joint;
      best_statistic = t.statistic;
      out.family = stats.statistics[static_cast<size_t>(t.statistic)].family;
    }
  }
  return out;
}

std::string ExplainThresholds(const ThresholdStats& stats, const RunScore& score, const std::string& family, int joint) {
  const std::string named = score.detected ? score.family + " on joint " + std::to_string(score.joint) + " at " +
                                                 Ms(score.detection_time_s) + " s"
                                           : "";
  // The first statistic over its threshold: what alarmed.
  auto first_over = [&](bool before_onset) -> std::string {
    for (const ThresholdStats::Trace& t : stats.traces) {
      const StatisticInfo& info = stats.statistics[static_cast<size_t>(t.statistic)];
      if (before_onset ? t.pre_max > info.threshold : FirstAlarm(t, info.threshold) != nullptr) {
        return info.name + " of joint " + std::to_string(t.joint) + " above " + Rounded(info.threshold);
      }
    }
    return "";
  };
  if (family.empty()) {
    if (!score.detected && !score.alarm_before_onset) return "";
    const std::string what = first_over(score.alarm_before_onset);
    return "false alarm: " + (named.empty() ? std::string("the monitor alarmed") : named) +
           (what.empty() ? "" : " (" + what + ")");
  }
  if (!score.detected) {
    // The faulted joint's statistic that came closest: its largest value from the onset on
    // (the last rise) over its threshold.
    double best_ratio = -kInf;
    std::string closest;
    for (const ThresholdStats::Trace& t : stats.traces) {
      if (t.joint != joint || t.rise.empty()) continue;
      const StatisticInfo& info = stats.statistics[static_cast<size_t>(t.statistic)];
      const double ratio = t.rise.back().value / info.threshold;
      if (ratio > best_ratio) {
        best_ratio = ratio;
        closest = info.name + " of joint " + std::to_string(joint) + " reached " + Rounded(t.rise.back().value) +
                  " at most, " + FormatNumber(std::round(ratio * 1000) / 10) + " % of its threshold " +
                  Rounded(info.threshold);
      }
    }
    if (closest.empty()) {
      return "no alarm: no statistic of joint " + std::to_string(joint) + " came within a factor " +
             FormatNumber(std::exp2(static_cast<double>(kLevelSteps) / kLevelsPerOctave)) +
             " of its threshold from the onset on";
    }
    return "no alarm: " + closest;
  }
  if (score.joint != joint) return "named the wrong joint: " + named;
  if (score.family != family) return "named " + named + " instead";
  return "";
}

}  // namespace armfault
