#include "core/monitors/detector_statistics.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <stdexcept>
#include <tuple>

#include "core/base/json_input.h"
#include "core/monitors/power_monitor.h"

namespace armfault {

const std::array<DetectorInfo, kDetectorCount>& Detectors() {
  static const std::array<DetectorInfo, kDetectorCount> d = {{
      {Detector::kKtFactor, "kt_degradation", "kt_factor", 1.0},
      {Detector::kResistanceFactor, "winding_resistance", "resistance_factor", 1.0},
      {Detector::kFrictionFactor, "friction_increase", "friction_factor", 1.0},
      {Detector::kSensorDrift, "torque_sensor_drift", "sensor_drift_Nm", 0.0},
  }};
  return d;
}

const DetectorInfo& DetectorByParameter(const std::string& parameter) {
  std::string known;
  for (const DetectorInfo& d : Detectors()) {
    if (parameter == d.parameter) return d;
    known += std::string(known.empty() ? "" : ", ") + d.parameter;
  }
  throw std::out_of_range("unknown detector parameter \"" + parameter + "\" (known: " + known + ")");
}

StateLimits MonitorConfig::*LimitsOf(Detector d) {
  switch (d) {
    case Detector::kKtFactor: return &MonitorConfig::kt_factor;
    case Detector::kResistanceFactor: return &MonitorConfig::resistance_factor;
    case Detector::kFrictionFactor: return &MonitorConfig::friction_factor;
    case Detector::kSensorDrift: return &MonitorConfig::sensor_drift_Nm;
  }
  return &MonitorConfig::kt_factor;
}

double ThresholdFor(const DetectorInfo& info, double worn_limit) { return std::fabs(worn_limit - info.healthy); }

DetectorThresholds ThresholdsOf(const MonitorConfig& config) {
  DetectorThresholds h{};
  for (const DetectorInfo& d : Detectors()) {
    h[static_cast<int>(d.detector)] = ThresholdFor(d, (config.*LimitsOf(d.detector)).worn);
  }
  return h;
}

double Quantize(double statistic, double quantum) {
  if (std::isnan(statistic) || statistic == kNoStatistic) return kNoStatistic;
  // Bounded so that held values fit a JSON integer exactly.
  return std::floor(std::min(statistic, 1e12 * quantum) / quantum);
}

double SlidingMin::Push(double value) {
  const long k = count_++;
  while (!q_.empty() && q_.back().second >= value) q_.pop_back();
  q_.emplace_back(k, value);
  while (q_.front().first <= k - span_) q_.pop_front();
  return q_.front().second;
}

nlohmann::json ToJson(const DecisionStats& s) {
  nlohmann::json traces = nlohmann::json::array();
  for (const DecisionStats::Trace& t : s.traces) {
    nlohmann::json rise = nlohmann::json::array(), pre = nlohmann::json::array();
    for (const DecisionStats::Rise& r : t.rise) {
      nlohmann::json item = {RoundToMicroseconds(r.t_s), r.held.quanta, r.held.significance_quanta};
      if (!r.family.empty()) item.push_back(r.family);
      rise.push_back(std::move(item));
    }
    for (const DecisionStats::Point& p : t.pre) pre.push_back({p.quanta, p.significance_quanta});
    traces.push_back({{"joint", t.joint},
                      {"detector", Detectors()[static_cast<int>(t.detector)].parameter},
                      {"pre", std::move(pre)},
                      {"rise", std::move(rise)}});
  }
  nlohmann::json events = nlohmann::json::array();
  for (const DecisionStats::Event& e : s.events) events.push_back({{"joint", e.joint}, {"family", e.family}, {"t_s", RoundToMicroseconds(e.t_s)}});
  nlohmann::json j = {{"quantum", kStatisticQuantum},
                      {"significance_quantum", kSignificanceQuantum},
                      {"onset_s", s.onset_s},
                      {"first_tick_s", s.first_tick_s < 0 ? s.first_tick_s : RoundToMicroseconds(s.first_tick_s)},
                      {"traces", std::move(traces)},
                      {"events", std::move(events)}};
  if (s.sequential_tests > 0) {
    j["sequential_tests"] = s.sequential_tests;
    j["last_tick_s"] = RoundToMicroseconds(s.last_tick_s);
  }
  return j;
}

DecisionStats DecisionStatsFromJson(const nlohmann::json& j) {
  auto need = [](const nlohmann::json& o, const char* key) -> const nlohmann::json& {
    if (!o.is_object() || !o.contains(key)) throw std::runtime_error(std::string("decision: missing \"") + key + "\"");
    return o.at(key);
  };
  try {
    if (need(j, "quantum").get<double>() != kStatisticQuantum ||
        need(j, "significance_quantum").get<double>() != kSignificanceQuantum) {
      throw std::runtime_error("decision: statistics quantized to " + need(j, "quantum").dump() + " and " +
                               need(j, "significance_quantum").dump() + ", this armfault uses " +
                               std::to_string(kStatisticQuantum) + " and " + std::to_string(kSignificanceQuantum));
    }
    DecisionStats s;
    s.onset_s = need(j, "onset_s").get<double>();
    s.first_tick_s = need(j, "first_tick_s").get<double>();
    for (const nlohmann::json& t : need(j, "traces")) {
      DecisionStats::Trace trace;
      trace.joint = need(t, "joint").get<int>();
      trace.detector = DetectorByParameter(need(t, "detector").get<std::string>()).detector;
      for (const nlohmann::json& p : need(t, "pre")) trace.pre.push_back({p.at(0).get<long>(), p.at(1).get<long>()});
      for (const nlohmann::json& r : need(t, "rise")) {
        DecisionStats::Rise rise;
        rise.t_s = r.at(0).get<double>();
        rise.held = {r.at(1).get<long>(), r.at(2).get<long>()};
        if (r.size() > 3) rise.family = r.at(3).get<std::string>();
        trace.rise.push_back(std::move(rise));
      }
      s.traces.push_back(std::move(trace));
    }
    if (j.contains("sequential_tests")) {
      s.sequential_tests = j.at("sequential_tests").get<int>();
      if (s.sequential_tests < 1) throw std::runtime_error("decision: \"sequential_tests\" must be >= 1");
      s.last_tick_s = need(j, "last_tick_s").get<double>();
    }
    for (const nlohmann::json& e : need(j, "events")) {
      s.events.push_back({need(e, "joint").get<int>(), need(e, "family").get<std::string>(), need(e, "t_s").get<double>()});
    }
    return s;
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(std::string("decision: ") + e.what());
  } catch (const std::out_of_range& e) {
    throw std::runtime_error(std::string("decision: ") + e.what());
  }
}

DecisionRecorder::DecisionRecorder(int joints, double onset_s)
    : trace_index_(static_cast<size_t>(joints)), latched_(static_cast<size_t>(joints), false) {
  stats_.onset_s = onset_s;
  for (auto& row : trace_index_) row.fill(-1);
}

void DecisionRecorder::Record(double t_s, int joint, const DetectorReadings& readings,
                              const std::string& structural_family) {
  const bool after = t_s >= stats_.onset_s;
  if (after && stats_.first_tick_s < 0) stats_.first_tick_s = t_s;
  stats_.last_tick_s = t_s;
  if (!structural_family.empty() && !latched_[joint]) {
    latched_[joint] = true;
    stats_.events.push_back({joint + 1, structural_family, t_s});
  }
  for (int d = 0; d < kDetectorCount; ++d) {
    const DetectorReading& r = readings[d];
    if (r.held_quanta == kNoStatistic || r.held_significance_quanta == kNoStatistic) continue;
    int& index = trace_index_[joint][d];
    if (index < 0) {
      index = static_cast<int>(stats_.traces.size());
      DecisionStats::Trace t;
      t.joint = joint + 1;
      t.detector = static_cast<Detector>(d);
      stats_.traces.push_back(std::move(t));
    }
    DecisionStats::Trace& t = stats_.traces[index];
    const DecisionStats::Point p{static_cast<long>(r.held_quanta), static_cast<long>(r.held_significance_quanta)};
    auto dominates = [](const DecisionStats::Point& a, const DecisionStats::Point& b) {
      return a.quanta >= b.quanta && a.significance_quanta >= b.significance_quanta;
    };
    if (!after) {
      if (std::none_of(t.pre.begin(), t.pre.end(), [&](const DecisionStats::Point& q) { return dominates(q, p); })) {
        t.pre.erase(std::remove_if(t.pre.begin(), t.pre.end(), [&](const DecisionStats::Point& q) { return dominates(p, q); }),
                    t.pre.end());
        t.pre.push_back(p);
      }
    } else if (std::none_of(t.rise.rbegin(), t.rise.rend(),  // most ticks repeat the last record
                            [&](const DecisionStats::Rise& q) { return dominates(q.held, p); })) {
      const char* own = Detectors()[d].family;
      t.rise.push_back({t_s, p, std::string(r.family) == own ? "" : r.family});
    }
  }
}

bool AlarmedBefore(const DecisionStats::Trace& t, double threshold, double significance) {
  for (const DecisionStats::Point& p : t.pre) {
    if (Alarms(static_cast<double>(p.quanta), static_cast<double>(p.significance_quanta), threshold, significance)) return true;
  }
  return false;
}

const DecisionStats::Rise* FirstAlarm(const DecisionStats::Trace& t, double threshold, double significance) {
  for (const DecisionStats::Rise& r : t.rise) {
    if (Alarms(static_cast<double>(r.held.quanta), static_cast<double>(r.held.significance_quanta), threshold, significance)) {
      return &r;
    }
  }
  return nullptr;
}

DecisionOutcome Decide(const DecisionStats& s, const DetectorThresholds& h, double significance) {
  DecisionOutcome out;
  // The first alarm at or after the onset: (time, priority, joint); events come first.
  std::tuple<double, int, int> best{0, 0, 0};
  auto consider = [&](double t, int priority, int joint, const std::string& family) {
    const std::tuple<double, int, int> key{t, priority, joint};
    if (!out.detected || key < best) {
      out.detected = true;
      best = key;
      out.detection_time_s = t;
      out.joint = joint;
      out.family = family;
    }
  };
  for (const DecisionStats::Event& e : s.events) {
    if (e.t_s < s.onset_s) out.alarm_before_onset = true;
    if (s.first_tick_s >= 0) consider(std::max(e.t_s, s.first_tick_s), -1, e.joint, e.family);
  }
  for (const DecisionStats::Trace& t : s.traces) {
    const int d = static_cast<int>(t.detector);
    if (AlarmedBefore(t, h[d], significance)) out.alarm_before_onset = true;
    if (const DecisionStats::Rise* r = FirstAlarm(t, h[d], significance)) {
      consider(r->t_s, d, t.joint, r->family.empty() ? Detectors()[d].family : r->family);
    }
  }
  return out;
}

namespace {

std::string Fmt(double x, int significant = 3) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", significant, x);
  return buf;
}

std::string Percent(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f", 100 * std::max(0.0, fraction));
  return buf;
}

// What must happen before detector d may judge (the monitor's excitation gates).
std::string GateOf(Detector d, const MonitorConfig& c) {
  switch (d) {
    case Detector::kKtFactor:
      return "output energy below min_rotor_energy_J = " + Fmt(c.min_rotor_energy_J) + " J";
    case Detector::kResistanceFactor:
      return "copper-loss energy below min_copper_energy_J = " + Fmt(c.min_copper_energy_J) + " J";
    case Detector::kFrictionFactor:
      return "moving time in the torque-balance fit below min_balance_moving_s = " + Fmt(c.min_balance_moving_s) + " s";
    case Detector::kSensorDrift:
      return "less than 1 s of motion each way";
  }
  return "";
}

// The detector whose statistic names `family` (brake drag shows as friction); -1 for the
// families only tick-level detectors see.
int DetectorOfFamily(const std::string& family) {
  if (family == "brake_lock") return static_cast<int>(Detector::kFrictionFactor);
  for (const DetectorInfo& info : Detectors()) {
    if (family == info.family) return static_cast<int>(info.detector);
  }
  return -1;
}

// The rise of `joint` after the onset that came closest to alarming: the largest
// min(deviation / threshold, significance / z) over every detector.
std::string Closest(const DecisionStats& s, const DetectorThresholds& h, double z, int joint) {
  double best = -1;
  std::string text;
  for (const DecisionStats::Trace& t : s.traces) {
    if (t.joint != joint) continue;
    const int d = static_cast<int>(t.detector);
    for (const DecisionStats::Rise& r : t.rise) {
      const double dev = r.held.quanta * kStatisticQuantum, sig = r.held.significance_quanta * kSignificanceQuantum;
      const double score = std::min(h[d] > 0 ? dev / h[d] : 0.0, z > 0 ? sig / z : 1.0);
      if (score <= best) continue;
      best = score;
      text = std::string(Detectors()[d].parameter) + " deviated " + Fmt(dev) + " (threshold " + Fmt(h[d]) + ", " +
             Percent(dev / h[d]) + " %) with significance " + Fmt(sig) + " (needs " + Fmt(z) + ")";
    }
  }
  return text;
}

bool JudgedAfterOnset(const DecisionStats& s, int joint, int detector) {
  for (const DecisionStats::Trace& t : s.traces) {
    if (t.joint == joint && static_cast<int>(t.detector) == detector && !t.rise.empty()) return true;
  }
  return false;
}

}  // namespace

std::string ExplainOutcome(const DecisionStats& s, const DetectorThresholds& h, double z, const DecisionOutcome& d,
                           const std::string& family, int joint, const MonitorConfig& config) {
  const std::string at = d.detected ? " at " + Fmt(d.detection_time_s, 6) + " s" : "";
  if (family.empty()) {
    return d.detected ? "alarm: " + d.family + " on joint " + std::to_string(d.joint) + at : "";
  }
  if (d.detected && d.family == family && d.joint == joint) return "";
  std::string out;
  if (d.detected) {
    out = "named " + (d.family.empty() ? std::string("an unknown fault") : d.family) + " on joint " +
          std::to_string(d.joint) + at + " instead of " + family + " on joint " + std::to_string(joint);
  } else {
    out = "no alarm";
  }
  const std::string j = " on joint " + std::to_string(joint);
  const int own = DetectorOfFamily(family);
  if (own < 0) {
    out += "; the tick-level " + family + " detector never latched" + j;
  } else if (!JudgedAfterOnset(s, joint, own)) {
    out += "; " + std::string(Detectors()[own].parameter) + j + " was never judged after the onset (" +
           GateOf(static_cast<Detector>(own), config) + ")";
  }
  const std::string closest = Closest(s, h, z, joint);
  if (!closest.empty()) {
    out += "; closest" + j + ": " + closest;
  } else if (own >= 0) {
    out += "; no statistic" + j + " was judged after the onset";
  }
  return out;
}

}  // namespace armfault
