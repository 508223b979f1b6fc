#include "campaigns/running/run_pipeline.h"

#include <cmath>

#include "core/plant/drive/torque_sensor.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/base/rng.h"
#include "core/run_config.h"

namespace armfault {

namespace {

// Commissioning: 16 s, enough for several reversals of the slowest joint.
constexpr double kCommissioningDuration_s = 16.0;

// The model of a unit's or a run's robot: the campaign's robot (checked when the campaign was
// read) with draws applied, `what` naming them. A draw can take a body below a floor (a rotor
// inertia drawn under core/plant/robot/mass_properties.h's): the InputError then fails this run
// alone, and says that the draws did it.
std::shared_ptr<const ArmModel> DrawnModel(const RobotConfig& robot, const std::string& what) {
  try {
    return std::make_shared<const ArmModel>(robot);
  } catch (const InputError& e) {
    throw e.Edited([&](std::string*, std::string*, std::string* message) { *message = what + ": " + *message; });
  }
}

}  // namespace

nlohmann::json CommissioningMotion(const RobotConfig& robot) {
  nlohmann::json joints = nlohmann::json::object();
  for (size_t j = 0; j < robot.modules.size(); ++j) {
    const ModuleParams& m = robot.modules[j];
    // A sine pair peaks at 1.3 A: keep it within 70 % of the half range, 30 deg at most, about
    // the middle of the range; each joint at its own frequency so their accelerations differ.
    const double half = 0.5 * (m.max_angle_deg - m.min_angle_deg);
    const double amplitude = std::min(30.0, 0.7 * half / 1.3);
    joints[std::to_string(j + 1)] = {{"type", "sine_pair"},
                                     {"amplitude_deg", amplitude},
                                     {"omega_rad_s", 0.9 + 0.35 * static_cast<double>(j)},
                                     {"offset_deg", 0.5 * (m.max_angle_deg + m.min_angle_deg)}};
  }
  return joints;
}

UnitMonitor CommissionUnit(const Campaign& campaign, const CaseSpec& spec) {
  UnitMonitor out;
  try {
    const RobotConfig robot = UnitRobot(campaign, spec);
    const std::shared_ptr<const ArmModel> model_of_unit = DrawnModel(robot, "with this unit's tolerance draws");
    const ArmModel& model = *model_of_unit;
    InputContext context;
    context.source = "<commissioning>";
    RunSpec run;
    run.duration_s = kCommissioningDuration_s;
    // A fleet's unit has a seed of its own; a run that is its own unit derives one from its seed.
    run.seed = spec.unit >= 0 ? MixSeed(campaign.seed, 0x636f6d6dULL + static_cast<uint64_t>(spec.unit))
                              : MixSeed(spec.seed, 0x636f6d6dULL);
    const StatedTolerances stated = StatedOf(campaign);
    run.ambient_C = 0.5 * (stated.ambient_min_C + stated.ambient_max_C);
    run.joints.resize(robot.modules.size());
    const int on = campaign.commissioning_trajectory;
    if (on >= 0 && static_cast<size_t>(on) < campaign.loaded_trajectories.size()) {
      // On one of the campaign's trajectories, the work the unit does.
      run.duration_s = campaign.commissioning_duration_s;
      for (const auto& [joint, trajectory] : campaign.loaded_trajectories[on]) run.joints[joint - 1].trajectory = trajectory;
    } else {
      for (const auto& [joint, trajectory] :
           JointTrajectoriesFromJson(CommissioningMotion(robot), "/commissioning", robot, run.duration_s, context)) {
        run.joints[joint - 1].trajectory = trajectory;
      }
    }
    // Streamed tick by tick to the monitor (CommissioningSink); one that learns nothing from it
    // (no sink) still has its unit commissioned, so a unit that cannot be fails its runs alike.
    const std::unique_ptr<CommissioningSink> sink = campaign.monitor_model->BeginCommissioning(model.control_dt_s());
    std::vector<JointSignals> signals;
    const RunResult result = Simulate(model, run, [&](const Tick& tick) {
      if (!sink) return;
      signals.resize(tick.joints->size());
      for (size_t j = 0; j < signals.size(); ++j) signals[j] = (*tick.joints)[j].signals;
      sink->Tick(tick.t_s, signals);
    });
    if (!result.ok) {
      out.failure = result.failure_reason;
      return out;
    }
    out.model = sink ? sink->End(result.end_time_s) : nullptr;
    if (!out.model) out.model = campaign.monitor_model;  // a monitor that learns nothing from it
  } catch (const std::exception& e) {
    out.failure = e.what();
  }
  return out;
}

UnitMonitors::UnitMonitors(const Campaign& campaign)
    : campaign_(campaign),
      once_(new std::once_flag[static_cast<size_t>(std::max(0, campaign.variation.units))]),
      units_(static_cast<size_t>(std::max(0, campaign.variation.units))) {}

UnitMonitor UnitMonitors::For(const CaseSpec& spec) {
  if (!campaign_.commissioning) return {campaign_.monitor_model, ""};
  if (spec.unit < 0 || static_cast<size_t>(spec.unit) >= units_.size()) return CommissionUnit(campaign_, spec);
  const size_t u = static_cast<size_t>(spec.unit);
  std::call_once(once_[u], [&] { units_[u] = CommissionUnit(campaign_, spec); });
  return units_[u];
}

void ScoreCompoundElements(const MonitorOutput& output, RunRecord* r) {
  if (!r->is_compound()) return;
  for (nlohmann::json& e : r->compound) {
    if (!e.contains("onset_s") || !e["onset_s"].is_number()) {  // a conditional onset that never fired
      e["isolated"] = false;
      e["detection_time_s"] = nullptr;
      continue;
    }
    const double onset = e["onset_s"].get<double>();
    const std::string family = e.value("family", "");
    const int joint = e.value("joint", 0);
    std::optional<double> found;
    for (const Verdict& v : output.verdicts) {
      if (v.alarm && v.t_s >= onset && v.family == family && v.joint == joint) {
        found = v.t_s;
        break;
      }
    }
    e["isolated"] = found.has_value();
    e["detection_time_s"] = found ? nlohmann::json(RoundToMicroseconds(*found)) : nlohmann::json(nullptr);
  }
}

void ApplyScore(const RunScore& score, RunRecord* r) {
  r->alarm_before_onset = score.alarm_before_onset;
  r->detected = score.detected;
  if (!score.detected) return;
  r->detection_time_s = score.detection_time_s;
  if (!r->family.empty()) r->latency_s = score.detection_time_s - r->onset_s;
  r->isolated_family = score.family;
  r->isolated_joint = score.joint;
  r->magnitude_name = score.magnitude_name;
  r->magnitude_estimate = score.magnitude;
  r->confidence = score.confidence;
}

namespace {

// A case's run without its faults: duration, seed, ambient and the trajectory's joints.
RunSpec CaseRunSpec(const Campaign& campaign, const CaseSpec& cs, const ArmModel& model) {
  RunSpec spec;
  spec.duration_s = campaign.duration_s;
  spec.seed = cs.seed;
  spec.ambient_C = cs.ambient_C;
  spec.start = cs.warm_start ? ThermalStart::kWarm : ThermalStart::kCold;
  spec.joints.resize(static_cast<size_t>(model.joint_count()));
  for (const auto& [joint, trajectory] : campaign.loaded_trajectories[cs.trajectory]) {
    spec.joints[joint - 1].trajectory = trajectory;
  }
  return spec;
}

// The record's identity from the case.
RunRecord CaseRecord(const Campaign& campaign, const CaseSpec& cs) {
  RunRecord r;
  r.case_index = cs.index;
  r.run_id = cs.run_id;
  r.trajectory = campaign.trajectories[cs.trajectory].name;
  r.fault = cs.fault;
  r.group = cs.group;
  r.seed = cs.seed;
  r.engine = EngineName(campaign.robot.engine);
  r.repetition = cs.repetition;
  r.variation = cs.VariationJson();
  return r;
}

// The magnitude a fault's JSON gives for its family's magnitude key, if it gives a number.
std::optional<double> StatedMagnitude(const nlohmann::json& fault, const std::string& key) {
  if (key.empty() || !fault.contains(key) || !fault[key].is_number()) return std::nullopt;
  return fault[key].get<double>();
}

// The faults of a case as one set, their conditional onsets resolved on the run's own plant
// (faults/fault.h, ResolveConditionalOnsets, every fault acting), and the record's truth: the
// earliest onset of the faults that act; a set none of whose faults acts (a condition that never
// fired, or too late) is not injected and is scored against an onset after the last tick, so
// every alarm is before it. A single fault is a set of one, recorded with its own family, joint
// and magnitude; a compound one records each element in RunRecord::compound.
std::vector<std::shared_ptr<const Fault>> PrepareFaults(const Campaign& campaign, const CaseSpec& cs,
                                                        const ArmModel& model, RunRecord* r) {
  std::vector<std::shared_ptr<const Fault>> faults;
  if (cs.fault.is_null()) return faults;
  const bool compound = cs.fault.contains("compound");
  const std::vector<nlohmann::json> specs =
      compound ? cs.fault.at("compound").get<std::vector<nlohmann::json>>() : std::vector<nlohmann::json>{cs.fault};
  std::vector<std::unique_ptr<Fault>> made;
  std::vector<Fault*> conditional;
  for (size_t i = 0; i < specs.size(); ++i) {
    made.push_back(MakeFault(specs[i], compound ? "/fault/compound/" + std::to_string(i) : "/fault", model.config()));
    if (made.back()->timing().condition) conditional.push_back(made.back().get());
  }
  if (!conditional.empty()) {
    ResolveConditionalOnsets(model, CaseRunSpec(campaign, cs, model), conditional);
    r->conditional_onset = true;
  }
  const long last_tick = std::lround(campaign.duration_s / model.control_dt_s());
  const double end_s = static_cast<double>(last_tick) * model.control_dt_s();
  if (compound) {
    r->family = "compound";
    r->joint = 0;
    r->compound = nlohmann::json::array();
  }
  bool any_injected = false;
  std::string not_injected;
  for (size_t i = 0; i < made.size(); ++i) {
    const Fault& f = *made[i];
    const std::string why = NotInjectedReason(f, end_s);
    const std::string key = FaultMagnitudeKey(f.family());
    const std::optional<double> magnitude = StatedMagnitude(specs[i], key);
    const double fired = f.timing().fired_s;
    if (f.timing().condition && !std::isnan(fired) && (!r->onset_fired_s || fired < *r->onset_fired_s)) {
      r->onset_fired_s = fired;
    }
    if (why.empty()) {
      r->onset_s = any_injected ? std::min(r->onset_s, f.timing().onset_s) : f.timing().onset_s;
      any_injected = true;
    } else {
      not_injected += compound ? (not_injected.empty() ? "" : "; ") + std::string("element ") + std::to_string(i) + ": " + why
                               : why;
    }
    if (!compound) {
      r->family = f.family();
      r->joint = f.joint_index() + 1;
      r->magnitude_key = magnitude ? key : "";
      if (magnitude) r->magnitude = *magnitude;
      continue;
    }
    nlohmann::json e = {{"family", f.family()},
                        {"joint", f.joint_index() + 1},
                        {"onset_s", why.empty() ? nlohmann::json(RoundToMicroseconds(f.timing().onset_s))
                                                : nlohmann::json(nullptr)},
                        {"magnitude_key", magnitude ? nlohmann::json(key) : nlohmann::json(nullptr)},
                        {"magnitude", magnitude ? specs[i][key] : nlohmann::json(nullptr)}};
    if (f.timing().condition) {
      e["onset_fired_s"] = std::isnan(fired) ? nlohmann::json(nullptr) : nlohmann::json(RoundToMicroseconds(fired));
      e["not_injected_reason"] = why.empty() ? nlohmann::json(nullptr) : nlohmann::json(why);
    }
    r->compound.push_back(std::move(e));
  }
  if (!any_injected) {
    r->not_injected_reason = not_injected;
    r->onset_s = static_cast<double>(last_tick + 1) * model.control_dt_s();
  }
  for (std::unique_ptr<Fault>& f : made) faults.push_back(std::move(f));
  return faults;
}

}  // namespace

namespace {
// The plant of a case (its drawn robot, faults and run spec) into `p`, whose record holds the
// case's identity.
void PreparePlant(const Campaign& campaign, const CaseSpec& cs, PreparedRun* p) {
  p->model = DrawnModel(CaseRobot(campaign, cs), "with this run's tolerance draws and payload");
  p->faults = PrepareFaults(campaign, cs, *p->model, &p->record);
  p->spec = CaseRunSpec(campaign, cs, *p->model);
  if (!p->faults.empty()) p->spec.hardware = std::make_shared<FaultSchedule>(p->faults);
}
}  // namespace

PreparedRun PrepareCase(const Campaign& campaign, const CaseSpec& cs, UnitMonitors* units) {
  PreparedRun p;
  p.record = CaseRecord(campaign, cs);
  std::optional<UnitMonitors> own;
  if (!units) units = &own.emplace(campaign);
  const UnitMonitor unit = units->For(cs);
  if (!unit.model) {
    p.record.ok = false;
    p.record.failure_reason = CommissioningFailureReason(cs, unit.failure);
    return p;
  }
  p.monitor = unit.model;
  PreparePlant(campaign, cs, &p);
  return p;
}

// The shortest stretch on a rail that RunRecord::sensor_saturated_s counts: the built-in
// monitor's default rail_time_s, the time after which it would have read a rail as a stuck lead.
constexpr double kMinSaturation_s = 0.05;

namespace {
// Execute, with `monitor_model` null: no monitor (x.monitor, x.tap null, x.cost null), the
// plant, the sensor-saturation meter and the faults' effect meters only.
ExecutedRun ExecuteWith(const ArmModel& model, const RunSpec& spec, const std::vector<std::shared_ptr<const Fault>>& faults,
                        const MonitorModel* monitor_model, double onset_s, const TickObserver& also, bool keep_windows,
                        StatisticsObserver* statistics) {
  ExecutedRun x;
  // The monitor knows the nominal robot (payload and friction as designed) and what it learnt
  // on this unit while commissioning, not this run's truth. The tap beside it (scoring's)
  // knows the onset.
  if (monitor_model) {
    x.monitor = monitor_model->NewMonitor();
    x.monitor->KeepWindows(keep_windows);
    x.tap = x.monitor->NewDecisionTap(onset_s);
  }
  if (statistics) {
    if (x.tap) {
      x.tap->ShowStatistics(statistics);
    } else {
      statistics->Declare({}, model.joint_count());
    }
  }
  EffectRecorder effects(model, faults);
  // The monitor's own calls are timed (monitor_cost.jsonl); the tap is scoring's, not its.
  MonitorClock clock;
  std::vector<JointSignals> signals;
  // Each torque sensor's rails (its ADC's first and last codes, read through its mapping).
  std::vector<std::pair<double, double>> rails;
  for (int j = 0; j < model.joint_count(); ++j) {
    const TorqueSensorParams& ts = model.joint(j).params.torque_sensor;
    rails.emplace_back(TorqueFromAdcCode(ts, 0), TorqueFromAdcCode(ts, static_cast<int>(std::lround(std::pow(2.0, ts.adc_bits))) - 1));
  }
  const double tick_s = model.control_dt_s();
  const long min_ticks = std::max(1L, std::lround(kMinSaturation_s / tick_s));
  std::vector<long> stretch_ticks(rails.size(), 0);
  try {
    x.result = Simulate(model, spec, [&](const Tick& tick) {
      signals.resize(tick.joints->size());
      for (size_t j = 0; j < signals.size(); ++j) {
        const JointTick& jt = (*tick.joints)[j];
        signals[j] = jt.signals;
        const double reading = jt.signals.tau_sensor_Nm;
        const bool saturated = (reading >= rails[j].second - 1e-9 && jt.tau_true_Nm > reading) ||
                               (reading <= rails[j].first + 1e-9 && jt.tau_true_Nm < reading);
        // Only stretches of kMinSaturation_s count (an impact's tick or two on the rail is not
        // a motion that saturates the sensor).
        long& ticks = stretch_ticks[j];
        ticks = saturated ? ticks + 1 : 0;
        if (ticks >= min_ticks) x.sensor_saturated_s[static_cast<int>(j) + 1] += (ticks == min_ticks ? ticks : 1) * tick_s;
      }
      if (x.monitor) {
        clock.Start();
        x.monitor->Observe(tick.t_s, signals);
        clock.StopTick();
        if (x.tap) x.tap->AfterObserve(tick.t_s);
      }
      if (x.first_tick_s < 0 && tick.t_s >= onset_s) x.first_tick_s = tick.t_s;
      effects.Observe(tick);
      if (also) also(tick);
    });
    if (x.monitor) {
      clock.Start();
      x.monitor->Finish(x.result.end_time_s);
      clock.StopFinish();
      x.cost = clock.ToJson();
    }
  } catch (const MonitorFailure& e) {
    x.monitor_failure = e.what();
    return x;
  }
  x.effects = effects.Results();
  return x;
}
}  // namespace

ExecutedRun Execute(const ArmModel& model, const RunSpec& spec, const std::vector<std::shared_ptr<const Fault>>& faults,
                    const MonitorModel& monitor_model, double onset_s, const TickObserver& also, bool keep_windows,
                    StatisticsObserver* statistics) {
  return ExecuteWith(model, spec, faults, &monitor_model, onset_s, also, keep_windows, statistics);
}

namespace {
// The record's plant outcome: status, sensor saturation, each fault's effect and excitation.
RunRecord PlantRecord(const PreparedRun& p, const ExecutedRun& x) {
  RunRecord r = p.record;
  r.sensor_saturated_s = x.sensor_saturated_s;
  r.ok = x.result.ok;
  r.failure_reason = x.result.failure_reason;
  const bool compound = r.is_compound();
  // Each fault's own effect; a set is not excited only if none of its faults could act.
  if (!p.faults.empty()) {
    std::string reasons;
    bool any_excited = false;
    if (compound) r.effect = nlohmann::json::array();
    for (size_t i = 0; i < p.faults.size(); ++i) {
      // A condition that never fired: never acted.
      const bool injected = compound ? r.compound[i]["onset_s"].is_number() : r.injected();
      const std::string reason = injected ? NotExcitedReason(*p.faults[i], x.effects[i]) : "";
      if (!compound) {
        r.effect = x.effects[i].ToJson();
        r.not_excited_reason = reason;
        break;
      }
      r.effect.push_back(x.effects[i].ToJson());
      r.compound[i]["effect"] = x.effects[i].ToJson();
      r.compound[i]["excited"] = injected && reason.empty();
      if (!injected) continue;
      any_excited = any_excited || reason.empty();
      reasons += (reasons.empty() ? "" : "; ") + std::string("element ") + std::to_string(i) + ": " + reason;
    }
    if (compound) r.not_excited_reason = any_excited || !r.injected() ? "" : reasons;
  }
  return r;
}
}  // namespace

RunRecord ScoreRun(const PreparedRun& p, const ExecutedRun& x) {
  if (!x.monitor_failure.empty()) {
    RunRecord r = p.record;
    r.ok = false;
    r.failure_reason = "monitor " + p.monitor->type() + " failed: " + x.monitor_failure;
    return r;
  }
  RunRecord r = PlantRecord(p, x);
  const bool compound = r.is_compound();
  r.cost = x.cost;
  if (x.tap) r.decision = x.tap->Statistics();
  // A monitor that breaks the contract (a joint that does not exist, a NaN, time running
  // backwards) fails the run: its verdicts cannot be scored.
  const MonitorOutput& output = x.monitor->output();
  const std::string breach =
      CheckOutput(output, p.model->joint_count(), x.result.end_time_s, FaultFamilyNames());
  if (!breach.empty()) {
    r.ok = false;
    // Named by its source too (the library, the Python class): which monitor broke the contract.
    const std::string source = p.monitor->source();
    r.failure_reason =
        "monitor " + p.monitor->type() + (source.empty() ? "" : " " + source) + " emitted a bad verdict: " + breach;
    return r;
  }
  // Scored from the verdicts alone, as for any monitor (core/monitors/monitor.h).
  const RunScore score = ScoreVerdicts(output, r.onset_s, x.first_tick_s);
  ApplyScore(score, &r);
  if (compound) ScoreCompoundElements(output, &r);
  // Why a wrong one is wrong; a compound run against its earliest element (the one the first
  // alarm should have named; a condition that never fired has onset_s +infinity).
  if (!x.result.ok || !r.injected() || (compound && r.detected && IsolatedRight(r))) return r;
  std::string family = r.family;
  int joint = r.joint;
  if (compound && !p.faults.empty()) {
    size_t first = 0;
    for (size_t i = 1; i < p.faults.size(); ++i) {
      if (p.faults[i]->timing().onset_s < p.faults[first]->timing().onset_s) first = i;
    }
    family = p.faults[first]->family();
    joint = p.faults[first]->joint_index() + 1;
  } else if (compound) {
    // A replayed run (campaigns/data/replay.h) has no fault objects, only the recorded elements: the
    // earliest that acted (its onset_s a number), the first of equals as above.
    const nlohmann::json* first = nullptr;
    for (const nlohmann::json& e : r.compound) {
      if (!e.contains("onset_s") || !e["onset_s"].is_number()) continue;
      if (!first || e["onset_s"].get<double>() < (*first)["onset_s"].get<double>()) first = &e;
    }
    if (first) {
      family = first->value("family", "");
      joint = first->value("joint", 0);
    }
  }
  r.miss_reason = x.tap ? x.tap->Explain(score, family, joint) : ExplainFromVerdicts(score, family, joint);
  return r;
}

RunRecord RunCase(const Campaign& campaign, const CaseSpec& cs, const TickObserver& also, UnitMonitors* units,
                  MonitorOutput* output, StatisticsObserver* statistics) {
  RunRecord r;
  try {
    const PreparedRun prepared = PrepareCase(campaign, cs, units);
    if (!prepared.model) return prepared.record;  // its unit's commissioning failed
    r = prepared.record;
    const ExecutedRun executed =
        Execute(*prepared.model, prepared.spec, prepared.faults, *prepared.monitor, prepared.record.onset_s, also,
                output != nullptr, statistics);
    if (output && executed.monitor_failure.empty()) *output = executed.monitor->output();
    return ScoreRun(prepared, executed);
  } catch (const std::exception& e) {
    if (r.run_id.empty()) r = CaseRecord(campaign, cs);
    r.ok = false;
    r.failure_reason = std::string("run could not be set up: ") + e.what();
  }
  return r;
}

std::string CommissioningFailureReason(const CaseSpec& cs, const std::string& failure) {
  return "the commissioning run of " + (cs.unit >= 0 ? "unit " + std::to_string(cs.unit) : std::string("this run's unit")) +
         " failed: " + failure;
}

RunRecord RunCasePlant(const Campaign& campaign, const CaseSpec& cs, const TickObserver& also) {
  RunRecord r;
  try {
    PreparedRun prepared;
    prepared.record = CaseRecord(campaign, cs);
    PreparePlant(campaign, cs, &prepared);
    r = prepared.record;
    const ExecutedRun executed = ExecuteWith(*prepared.model, prepared.spec, prepared.faults, nullptr,
                                             prepared.record.onset_s, also, false, nullptr);
    return PlantRecord(prepared, executed);
  } catch (const std::exception& e) {
    if (r.run_id.empty()) r = CaseRecord(campaign, cs);
    r.ok = false;
    r.failure_reason = std::string("run could not be set up: ") + e.what();
  }
  return r;
}

}  // namespace armfault
