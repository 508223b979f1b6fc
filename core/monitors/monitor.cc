#include "core/monitors/monitor.h"

#include <cmath>

namespace armfault {

JointSignals SignalsOf(const JointTick& tick) {
  JointSignals s;
  s.q_ref_rad = tick.q_ref_rad;
  s.qd_ref_rad_s = tick.qd_ref_rad_s;
  s.q_meas_rad = tick.q_meas_rad;
  s.qd_est_rad_s = tick.qd_est_rad_s;
  s.tau_sensor_Nm = tick.tau_sensor_Nm;
  s.i_cmd_A = tick.i_cmd_A;
  s.i_supply_meas_A = tick.i_supply_meas_A;
  s.v_bus_meas_V = tick.v_bus_meas_V;
  s.winding_temp_C = tick.winding_temp_meas_C;
  return s;
}

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

TickObserver ObserveWith(HealthMonitor* monitor, TickObserver also) {
  return [monitor, also, signals = std::vector<JointSignals>()](const Tick& tick) mutable {
    signals.resize(tick.joints->size());
    for (size_t j = 0; j < signals.size(); ++j) signals[j] = SignalsOf((*tick.joints)[j]);
    monitor->Observe(tick.t_s, signals);
    if (also) also(tick);
  };
}

}  // namespace armfault
