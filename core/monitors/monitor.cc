#include "core/monitors/monitor.h"

#include <algorithm>
#include <cmath>

#include "core/base/json_input.h"

namespace armfault {

namespace {
std::string JoinNames(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}
}  // namespace

const char* HealthStateName(HealthState s) {
  switch (s) {
    case HealthState::kHealthy: return "healthy";
    case HealthState::kWorn: return "worn";
    case HealthState::kDefective: return "defective";
  }
  return "healthy";
}

Diagnosis Diagnose(const MonitorOutput& output) {
  Diagnosis d;
  for (const Verdict& v : output.verdicts) {
    if (!d.detected && v.alarm) {
      d.detected = true;
      d.detection_time_s = v.t_s;
      d.joint = v.joint;
    }
    if (d.detected && v.joint == d.joint && v.alarm) {
      d.family = v.family;
      d.magnitude_name = v.magnitude_name;
      d.magnitude = v.magnitude;
      d.confidence = v.confidence;
      d.state = v.state;
    }
  }
  return d;
}

RunScore ScoreVerdicts(const MonitorOutput& output, double onset_s, double first_tick_s) {
  RunScore score;
  std::vector<const Verdict*> standing;  // per joint: its latest verdict before the onset
  auto detect = [&](const Verdict& v, double t_s) {
    score.detected = true;
    score.detection_time_s = t_s;
    score.joint = v.joint;
    score.family = v.family;
  };
  for (const Verdict& v : output.verdicts) {
    if (v.t_s < onset_s) {
      if (v.alarm) score.alarm_before_onset = true;
      if (standing.size() < static_cast<size_t>(std::max(0, v.joint))) standing.resize(static_cast<size_t>(v.joint));
      if (v.joint >= 1) standing[static_cast<size_t>(v.joint - 1)] = &v;
      continue;
    }
    if (!score.detected) {
      // An alarm that stood at the onset is the first alarm from the onset on.
      for (const Verdict* s : standing) {
        if (s && s->alarm && first_tick_s >= 0 && first_tick_s <= v.t_s) {
          detect(*s, first_tick_s);
          break;
        }
      }
    }
    if (!score.detected && v.alarm) detect(v, v.t_s);
  }
  if (!score.detected && first_tick_s >= 0) {
    for (const Verdict* s : standing) {
      if (s && s->alarm) {
        detect(*s, first_tick_s);
        break;
      }
    }
  }
  if (!score.detected) return score;
  // The size: the joint's latest verdict of that family, refined while the alarm stands.
  for (const Verdict& v : output.verdicts) {
    if (v.joint != score.joint || v.family != score.family || !v.alarm) continue;
    score.magnitude_name = v.magnitude_name;
    score.magnitude = v.magnitude_name.empty() ? std::nullopt : std::optional<double>(v.magnitude);
    score.confidence = v.confidence;
  }
  return score;
}

std::string ExplainFromVerdicts(const RunScore& score, const std::string& family, int joint) {
  const std::string named = score.detected ? score.family + " on joint " + std::to_string(score.joint) + " at " +
                                                 FormatNumber(std::round(score.detection_time_s * 1e3) / 1e3) + " s"
                                           : "";
  if (family.empty()) {
    if (score.alarm_before_onset) return "false alarm (the monitor alarmed on a healthy run)";
    return score.detected ? "false alarm: " + named : "";
  }
  if (!score.detected) return "no alarm from the onset on (the monitor publishes no statistics to say how close it came)";
  if (score.joint != joint) return "named the wrong joint: " + named;
  if (score.family != family) return "named " + named + " instead";
  return "";
}

std::string CheckVerdict(const Verdict& v, int joints, double t_end_s, const std::vector<std::string>& families) {
  if (!std::isfinite(v.t_s)) return "time is not a finite number";
  // Half a microsecond of slack: times pass through decimal text.
  if (v.t_s < -5e-7 || v.t_s > t_end_s + 5e-7) {
    return "t_s " + FormatNumber(v.t_s) + " outside the run [0, " + FormatNumber(t_end_s) + "] s";
  }
  if (v.joint < 1 || v.joint > joints) {
    return "joint " + std::to_string(v.joint) + " out of range, expected 1.." + std::to_string(joints);
  }
  if (!std::isfinite(v.magnitude)) return "magnitude is not a finite number";
  if (!std::isfinite(v.confidence) || v.confidence < 0 || v.confidence > 1) {
    return "confidence " + FormatNumber(v.confidence) + " outside [0, 1]";
  }
  if (v.alarm != (v.state != HealthState::kHealthy)) return "alarm and state disagree";
  if (v.alarm && v.family != "unknown" && std::find(families.begin(), families.end(), v.family) == families.end()) {
    return "unknown fault family \"" + v.family + "\" (known: " + JoinNames(families) + ", unknown)";
  }
  return "";
}

std::string CheckOutput(const MonitorOutput& output, int joints, double t_end_s,
                        const std::vector<std::string>& families) {
  double t_prev_s = 0;
  for (size_t k = 0; k < output.verdicts.size(); ++k) {
    const Verdict& v = output.verdicts[k];
    const std::string where = "verdict " + std::to_string(k + 1) + " (t_s " + FormatNumber(v.t_s) + ", joint " +
                              std::to_string(v.joint) + "): ";
    if (const std::string why = CheckVerdict(v, joints, t_end_s, families); !why.empty()) return where + why;
    if (v.t_s < t_prev_s) return where + "time goes backwards (previous verdict at " + FormatNumber(t_prev_s) + " s)";
    t_prev_s = v.t_s;
  }
  return "";
}

namespace {
nlohmann::json NumberOrNull(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }
}  // namespace

nlohmann::json ToJson(const Verdict& v) {
  return {{"t_s", v.t_s},
          {"joint", v.joint},
          {"state", HealthStateName(v.state)},
          {"alarm", v.alarm},
          {"family", v.family.empty() ? nlohmann::json(nullptr) : nlohmann::json(v.family)},
          {"magnitude_name", v.magnitude_name.empty() ? nlohmann::json(nullptr) : nlohmann::json(v.magnitude_name)},
          {"magnitude", v.magnitude_name.empty() ? nlohmann::json(nullptr) : NumberOrNull(v.magnitude)},
          {"confidence", v.confidence}};
}

nlohmann::json ToJson(const EfficiencyWindow& w) {
  return {{"joint", w.joint},
          {"t_start_s", w.t_start_s},
          {"t_end_s", w.t_end_s},
          {"direction", w.direction},
          {"flow", w.flow},
          {"used", w.used},
          {"out_J", w.out_J},
          {"rotor_J", w.rotor_J},
          {"friction_J", w.friction_J},
          {"mesh_in_J", w.mesh_in_J},
          {"mesh_loss_J", w.mesh_loss_J},
          {"supply_J", w.supply_J},
          {"electrical_loss_J", w.electrical_loss_J},
          {"eta", NumberOrNull(w.eta)},
          {"eta_m", NumberOrNull(w.eta_m)},
          {"eta_e", NumberOrNull(w.eta_e)},
          {"eta_expected", NumberOrNull(w.eta_expected)},
          {"eta_m_expected", NumberOrNull(w.eta_m_expected)},
          {"eta_e_expected", NumberOrNull(w.eta_e_expected)}};
}

nlohmann::json ToJson(const Diagnosis& d) {
  nlohmann::json j = {{"detected", d.detected}};
  j["detection_time_s"] = d.detected ? nlohmann::json(d.detection_time_s) : nlohmann::json(nullptr);
  j["isolated_joint"] = d.detected ? nlohmann::json(d.joint) : nlohmann::json(nullptr);
  j["isolated_family"] = d.detected ? nlohmann::json(d.family) : nlohmann::json(nullptr);
  j["magnitude_name"] = d.detected && !d.magnitude_name.empty() ? nlohmann::json(d.magnitude_name) : nlohmann::json(nullptr);
  j["magnitude_estimate"] = d.detected && !d.magnitude_name.empty() ? NumberOrNull(d.magnitude) : nlohmann::json(nullptr);
  j["confidence"] = d.detected ? nlohmann::json(d.confidence) : nlohmann::json(nullptr);
  j["state"] = HealthStateName(d.state);
  return j;
}

nlohmann::json ToJson(const MonitorOutput& output) {
  nlohmann::json out = {{"diagnosis", ToJson(Diagnose(output))},
                        {"verdicts", nlohmann::json::array()},
                        {"windows", nlohmann::json::array()}};
  for (const Verdict& v : output.verdicts) out["verdicts"].push_back(ToJson(v));
  for (const EfficiencyWindow& w : output.windows) out["windows"].push_back(ToJson(w));
  return out;
}

}  // namespace armfault
