#include "campaigns/data/twin_compare.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "campaigns/data/log_reference.h"
#include "campaigns/data/replay.h"
#include "core/base/json_input.h"
#include "core/plant/simulation.h"

namespace armfault {

namespace fs = std::filesystem;

const TwinSignal* JointComparison::Find(const std::string& key) const {
  for (const TwinSignal& s : signals) {
    if (s.key == key) return &s;
  }
  return nullptr;
}

namespace {

// One signal of a joint, as a function of its JointSignals.
struct SignalSpec {
  const char* key;
  const char* label;
  const char* unit;
  double (*of)(const JointSignals&);
};
const SignalSpec kSignals[] = {
    {"supply_power_W", "supply power U_d·I_d", "W", [](const JointSignals& s) { return s.v_bus_meas_V * s.i_supply_meas_A; }},
    {"supply_current_A", "supply current I_d", "A", [](const JointSignals& s) { return s.i_supply_meas_A; }},
    {"commanded_current_A", "commanded current i", "A", [](const JointSignals& s) { return s.i_cmd_A; }},
    {"torque_sensor_Nm", "torque-sensor reading τ_s", "N m", [](const JointSignals& s) { return s.tau_sensor_Nm; }},
    {"tracking_error_mrad", "tracking error q_ref − q_meas", "mrad",
     [](const JointSignals& s) { return 1e3 * (s.q_ref_rad - s.q_meas_rad); }},
};

void Score(TwinSignal* s) {
  double rr = 0, tt = 0, ee = 0, e = 0;
  long n = 0;
  for (size_t k = 0; k < s->recorded.size(); ++k) {
    const double r = s->recorded[k], t = s->twin[k];
    if (!std::isfinite(r) || !std::isfinite(t)) continue;
    rr += r * r, tt += t * t, ee += (r - t) * (r - t), e += r - t;
    ++n;
  }
  s->compared_ticks = n;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  s->recorded_rms = n > 0 ? std::sqrt(rr / n) : nan;
  s->twin_rms = n > 0 ? std::sqrt(tt / n) : nan;
  s->residual_rms = n > 0 ? std::sqrt(ee / n) : nan;
  s->residual_mean = n > 0 ? e / n : nan;
}

}  // namespace

TwinComparison CompareWithTwin(const RobotConfig& twin, double control_dt_s, const std::vector<double>& t_s,
                               const std::vector<std::vector<JointSignals>>& log, uint64_t seed, const std::string& source) {
  const std::vector<std::vector<JointSignals>> sim = SimulateAlongLog(twin, control_dt_s, log, seed, source);
  TwinComparison c;
  c.twin_name = twin.name;
  c.control_dt_s = control_dt_s;
  c.seed = seed;
  c.t_s = t_s;
  // The twin's ticks are the log's (t = k × period from the first): compare row by row.
  const size_t ticks = std::min(log.size(), sim.size());
  c.t_s.resize(ticks);
  for (size_t j = 0; j < twin.modules.size(); ++j) {
    JointComparison jc;
    jc.joint = static_cast<int>(j) + 1;
    for (const SignalSpec& spec : kSignals) {
      TwinSignal s;
      s.key = spec.key, s.label = spec.label, s.unit = spec.unit;
      s.recorded.reserve(ticks), s.twin.reserve(ticks);
      bool recorded_any = false;
      for (size_t k = 0; k < ticks; ++k) {
        s.recorded.push_back(spec.of(log[k][j]));
        s.twin.push_back(spec.of(sim[k][j]));
        recorded_any = recorded_any || std::isfinite(s.recorded.back());
      }
      // A joint without the sensor (an empty column, NaN in the twin): nothing to compare.
      if (!recorded_any) continue;
      Score(&s);
      jc.signals.push_back(std::move(s));
    }
    c.joints.push_back(std::move(jc));
  }
  return c;
}

TwinComparison CompareRecordedRun(const TwinCompareOptions& o) {
  const fs::path dir(o.recorded_dir);
  const fs::path manifest = dir / "manifest.jsonl";
  const RobotConfig recorded = RecordedRobot(o.recorded_dir, "the robot the runs were recorded with (an export's or an import's)");
  const std::vector<nlohmann::json> lines = ManifestLines(o.recorded_dir);
  if (lines.empty()) throw InputError(manifest.string(), "", "holds no run to compare the twin with");
  auto healthy = [](const nlohmann::json& line) {
    const auto f = line.find("family");
    const bool labelled_unknown = line.contains("label") && line["label"].is_string() &&
                                  (line["label"] == "unknown" || line["label"] == "unlabelled");
    return f != line.end() && (f->is_null() || *f == "" || *f == "healthy") && !labelled_unknown;
  };
  std::string why;
  nlohmann::json line;
  if (!o.run_id.empty()) {
    line = ManifestLine(o.recorded_dir, o.run_id, o.run_option);
    why = "chosen with " + o.run_option;
  } else {
    // The run the twin was calibrated on, when its calibration says so and the manifest has it.
    fs::path sidecar(o.twin_file);
    sidecar.replace_extension(".calibration.json");
    if (fs::is_regular_file(sidecar)) {
      const nlohmann::json cal = ReadJsonFile(sidecar.string());
      if (cal.is_object() && cal.contains("run_id") && cal["run_id"].is_string()) {
        for (const nlohmann::json& l : lines) {
          if (l["run_id"] == cal["run_id"]) line = l, why = "the run the twin was calibrated on (" + sidecar.string() + ")";
        }
      }
    }
    for (const nlohmann::json& l : lines) {
      if (line.is_null() && healthy(l)) line = l, why = "the first healthy run of " + manifest.string();
    }
    if (line.is_null()) line = lines.front(), why = "the first run of " + manifest.string() + " (none is labelled healthy)";
  }
  const std::string run = line["run_id"].get<std::string>();
  if (!line.contains("signals") || !line["signals"].is_string()) {
    throw InputError(manifest.string(), "", "run \"" + run + "\" names no \"signals\" file");
  }
  // The twin must be of the recorded robot: its joints and its control clock.
  const ArmModel recorded_arm(recorded), twin_arm(o.twin);
  const std::string recorded_source = (dir / "campaign.json").string() + " /campaign/robot";
  if (twin_arm.joint_count() != recorded_arm.joint_count()) {
    throw InputError(o.twin_file, "/modules", "the twin has " + std::to_string(twin_arm.joint_count()) +
                                                  " joints; the recorded robot \"" + recorded.name + "\" (" + recorded_source +
                                                  ") has " + std::to_string(recorded_arm.joint_count()));
  }
  const double dt = recorded_arm.control_dt_s();
  if (std::fabs(twin_arm.control_dt_s() - dt) > 1e-9) {
    throw InputError(o.twin_file, "", "the twin's control period is " + FormatNumber(twin_arm.control_dt_s()) +
                                          " s; the recorded robot's (" + recorded_source + ") is " + FormatNumber(dt) + " s");
  }
  const fs::path signals = dir / line["signals"].get<std::string>();
  std::vector<std::vector<JointSignals>> ticks;
  std::vector<double> t_s;
  ReadSignalsAtControlRate(signals.string(), recorded_arm.joint_count(), dt, &ticks, &t_s);
  if (ticks.size() < 2) throw InputError(signals.string(), "", "holds " + std::to_string(ticks.size()) + " ticks: no motion to compare");
  TwinComparison c = CompareWithTwin(o.twin, dt, t_s, ticks, o.seed, signals.string());
  c.run_id = run;
  c.why = why;
  c.twin_file = o.twin_file;
  c.signals_file = signals.string();
  if (line.contains("family") && line["family"].is_string() && line["family"] != "healthy") c.family = line["family"].get<std::string>();
  if (!c.family.empty() && line.contains("onset_s") && line["onset_s"].is_number()) c.onset_s = line["onset_s"].get<double>();
  return c;
}

}  // namespace armfault
