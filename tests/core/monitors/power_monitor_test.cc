// The power-efficiency monitor: its efficiencies against the simulator's truth, silence on
// healthy motions it was not tuned on, detection, isolation and sizing of each family, and
// its configuration errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/monitors/commissioning.h"
#include "core/monitors/power_monitor.h"
#include "core/observe.h"
#include "core/run_config.h"
#include "faults/fault.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;
using testing_support::Recording;

struct MonitoredRun {
  RunResult result;
  MonitorOutput output;
  Diagnosis diagnosis;
  PowerEfficiencyMonitor::Estimates top;  // joint 3's final estimates
  std::vector<PowerEfficiencyMonitor::Estimates> all;  // every joint's
  Recording rec;
};

// Runs `run_json` (a run file as `armfault trace` reads it) with the default monitor.
// `noise_scale` multiplies every module's torque-sensor and supply-current noise.
// `sensor_offset_Nm`: joint `offset_joint`'s torque sensor reads that much more than the
// monitor's calibration holds, from the start (a temperature the calibration was not made at).
MonitoredRun RunMonitored(const json& run_json, double payload_kg = -1, bool record = false, double noise_scale = 1,
                          double sensor_offset_Nm = 0, int offset_joint = 3, double ambient_C = 20,
                          ThermalStart start = ThermalStart::kCold, bool commission = false,
                          bool reverse_joint_order = false) {
  InputContext context;
  context.source = "<test>";
  RunConfig run = RunConfigFromJson(run_json, "", context);
  if (payload_kg >= 0) run.robot.payload_kg = payload_kg;
  if (sensor_offset_Nm != 0) run.robot.modules.at(offset_joint - 1).torque_sensor.offset_error_Nm = sensor_offset_Nm;
  for (ModuleParams& m : run.robot.modules) {
    m.torque_sensor.noise_Nm *= noise_scale;
    m.inverter.supply_current_noise_A *= noise_scale;
  }
  const ArmModel model(run.robot);
  std::vector<std::shared_ptr<const Fault>> faults;
  for (auto& f : MakeFaults(run.faults_json, "/faults", run.robot)) faults.push_back(std::move(f));
  RunSpec spec = MakeRunSpec(run);
  spec.ambient_C = ambient_C;
  spec.start = start;
  if (!faults.empty()) spec.hardware = std::make_shared<FaultSchedule>(faults);
  PowerMonitorModel monitor_model =
      MakePowerMonitorModel(run.robot, MonitorConfigFromJson(run.monitor.settings, "/monitor", "<test>"));
  if (commission) {
    // `commission`: as a campaign does, on the same motion (up to 20 s), healthy, cold at 20 degC,
    // another seed.
    PowerMonitorCommissioning fit(monitor_model, monitor_model.control_dt_s);
    RunSpec healthy = MakeRunSpec(run);
    healthy.seed += 1000;
    healthy.duration_s = std::min(healthy.duration_s, 20.0);
    std::vector<JointSignals> s;
    const RunResult c = Simulate(model, healthy, [&](const Tick& tick) {
      s.clear();
      for (const JointTick& jt : *tick.joints) s.push_back(jt.signals);
      fit.Tick(s);
    });
    EXPECT_TRUE(c.ok) << c.failure_reason;
    monitor_model = fit.End();
  }
  PowerEfficiencyMonitor monitor(monitor_model);
  monitor.UpdateJointsInReverseOrder(reverse_joint_order);
  MonitoredRun out;
  out.result = Simulate(model, spec, ObserveWith(&monitor, record ? out.rec.Observer() : TickObserver()));
  monitor.Finish(out.result.end_time_s);
  out.output = monitor.output();
  out.diagnosis = Diagnose(out.output);
  out.top = monitor.estimates(2);
  for (int j = 0; j < monitor.joint_count(); ++j) out.all.push_back(monitor.estimates(j));
  return out;
}

json Exp1(json faults = json::array(), uint64_t seed = 1) {
  json run = ThesisExperiment1Json();
  run["faults"] = faults;
  run["seed"] = seed;
  return run;
}

json Fault(json fault, int joint = 3, double onset_s = 2.0) {
  fault["joint"] = joint;
  fault["onset_s"] = onset_s;
  return json::array({fault});
}

// --- cross-check against the truth -----------------------------------------------------

TEST(PowerMonitorCrossCheck, WindowEnergiesAndEfficienciesMatchTheTruth) {
  const MonitoredRun run = RunMonitored(Exp1(), -1, /*record=*/true);
  ASSERT_TRUE(run.result.ok);
  int judged = 0;
  for (const EfficiencyWindow& w : run.output.windows) {
    if (!w.used || w.joint != 3) continue;
    ++judged;
    // The same window from the simulator's true powers (means over each control period).
    double out = 0, emf = 0, supply = 0;
    for (size_t k = 0; k < run.rec.t.size(); ++k) {
      const double t = run.rec.t[k];
      if (t <= w.t_start_s + 1e-9 || t > w.t_end_s + 1e-9) continue;
      const JointTick& j = run.rec.ticks[k][2];
      out += j.p_mech_out_W * 0.002;
      emf += j.p_emf_W * 0.002;
      supply += j.p_supply_W * 0.002;
    }
    SCOPED_TRACE(testing::Message() << "window " << w.t_start_s << "-" << w.t_end_s << " " << w.flow);
    EXPECT_NEAR(w.out_J, out, 0.02 * std::fabs(out) + 0.02);
    EXPECT_NEAR(w.rotor_J, emf, 0.03 * std::fabs(emf) + 0.05);
    EXPECT_NEAR(w.supply_J, supply, 0.01 * std::fabs(supply) + 0.02);
    // Measured efficiency against the healthy expectation: a healthy joint matches it.
    EXPECT_NEAR(w.eta_m, w.eta_m_expected, 0.02);
    if (w.flow == "forward") {
      EXPECT_NEAR(w.eta_e, emf / supply, 0.02);
      EXPECT_NEAR(w.eta_e, w.eta_e_expected, 0.02);
      EXPECT_NEAR(w.eta, w.eta_expected, 0.02);
    }
  }
  EXPECT_GE(judged, 4);  // two lifting and at least two lowering windows
  EXPECT_NEAR(run.top.kt_factor, 1.0, 0.02);
  EXPECT_NEAR(run.top.friction_factor, 1.0, 0.05);
}

TEST(PowerMonitorCrossCheck, ForwardAndReverseMeshEfficienciesFollowTheLossModel) {
  // 24 % mesh loss of the transmitted torque: forward 1/1.24, reverse 1 - 0.24.
  const MonitoredRun run = RunMonitored(Exp1());
  int forward = 0, reverse = 0;
  for (const EfficiencyWindow& w : run.output.windows) {
    if (!w.used) continue;
    if (w.flow == "forward") {
      ++forward;
      EXPECT_NEAR(w.eta_m, 1 / 1.24, 0.02);
    } else if (w.flow == "reverse") {
      ++reverse;
      EXPECT_NEAR(w.eta_m, 0.76, 0.02);
      EXPECT_TRUE(std::isnan(w.eta_e));  // the motor still drives: no regeneration to rate
    }
  }
  EXPECT_GE(forward, 2);
  EXPECT_GE(reverse, 2);
}

// --- healthy motions the monitor was not tuned on -------------------------------------

struct HealthyCase {
  const char* name;
  json joints;
};

class PowerMonitorHealthy : public testing::TestWithParam<HealthyCase> {};

TEST_P(PowerMonitorHealthy, NoAlarmForAnyPayloadSeedOrSensorNoise) {
  // Payloads around the tool's 2 kg; seed 12 also with three times the sensor noise.
  for (double payload : {1.5, 2.5}) {
    for (uint64_t seed : {11, 12}) {
      json run = {{"robot", "mrr-config1"}, {"duration_s", 10}, {"seed", seed}, {"joints", GetParam().joints}};
      const MonitoredRun r = RunMonitored(run, payload, false, seed == 12 ? 3.0 : 1.0);
      ASSERT_TRUE(r.result.ok) << r.result.failure_reason;
      EXPECT_FALSE(r.diagnosis.detected) << "payload " << payload << " kg, seed " << seed << ": alarm at "
                                         << r.diagnosis.detection_time_s << " s, joint " << r.diagnosis.joint << " "
                                         << r.diagnosis.family << " " << r.diagnosis.magnitude;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Motions, PowerMonitorHealthy,
    testing::Values(
        HealthyCase{"fast_small_sine", {{"3", {{"type", "sine_pair"}, {"amplitude_deg", 10}, {"omega_rad_s", 3}}}}},
        HealthyCase{"two_joint_ramp",
                    {{"2", {{"type", "cosine_ramp"}, {"amplitude_deg", 25}, {"period_s", 40}}},
                     {"3", {{"type", "cosine_ramp"}, {"amplitude_deg", 25}, {"period_s", 40}}}}},
        HealthyCase{"point_to_point",
                    {{"2", {{"type", "min_jerk"}, {"waypoints", {{0, 0}, {3, 30}, {7, -20}, {10, 0}}}}},
                     {"3", {{"type", "cosine_ramp"}, {"amplitude_deg", 20}, {"period_s", 5}}}}},
        HealthyCase{"base_and_dwell",
                    {{"1", {{"type", "sine_pair"}, {"amplitude_deg", 40}, {"omega_rad_s", 1}}},
                     {"3", {{"type", "min_jerk"}, {"waypoints", {{0, 0}, {2, -40}, {4, -40}, {6, 30}, {10, 0}}}}}}},
        HealthyCase{"second_joint_sine", {{"2", {{"type", "sine_pair"}, {"amplitude_deg", 15}, {"omega_rad_s", 2}}}}}),
    [](const testing::TestParamInfo<HealthyCase>& info) { return std::string(info.param.name); });

// --- detection, isolation, magnitude ---------------------------------------------------

void ExpectDiagnosis(const MonitoredRun& r, const std::string& family, int joint, double onset_s,
                     double within_s = 4.0) {
  ASSERT_TRUE(r.diagnosis.detected) << family;
  EXPECT_EQ(r.diagnosis.family, family);
  EXPECT_EQ(r.diagnosis.joint, joint);
  EXPECT_GE(r.diagnosis.detection_time_s, onset_s);  // no alarm before the fault
  EXPECT_LT(r.diagnosis.detection_time_s, onset_s + within_s);
}

TEST(PowerMonitorDetects, KtDegradationWithItsFactor) {
  for (double n : {0.7, 0.5}) {
    const MonitoredRun r = RunMonitored(Exp1(Fault({{"family", "kt_degradation"}, {"kt_factor", n}})));
    ExpectDiagnosis(r, "kt_degradation", 3, 2.0);
    EXPECT_EQ(r.diagnosis.magnitude_name, "kt_factor");
    EXPECT_NEAR(r.diagnosis.magnitude, n, 0.1 * n) << n;
  }
}

TEST(PowerMonitorDetects, KtDegradationOnTheSecondJointIsIsolatedThere) {
  json run = {{"robot", "mrr-config1"},
              {"duration_s", 10},
              {"joints", {{"2", {{"type", "sine_pair"}, {"amplitude_deg", 15}, {"omega_rad_s", 2}}}}},
              {"faults", Fault({{"family", "kt_degradation"}, {"kt_factor", 0.7}}, 2)}};
  const MonitoredRun r = RunMonitored(run);
  ExpectDiagnosis(r, "kt_degradation", 2, 2.0);
  EXPECT_NEAR(r.diagnosis.magnitude, 0.7, 0.07);
}

TEST(PowerMonitorDetects, FrictionIncreaseWithItsFactor) {
  // (At 2x and more of the whole friction this run's wear is named a sensor drift: 0.77 s after
  // the onset the sensor's zero is not found yet, and within one direction of motion friction
  // and an offset are one; docs/monitor.md, "The friction magnitude".)
  const MonitoredRun r = RunMonitored(Exp1(Fault({{"family", "friction_increase"}, {"friction_factor", 1.5}})));
  ExpectDiagnosis(r, "friction_increase", 3, 2.0);
  EXPECT_EQ(r.diagnosis.magnitude_name, "friction_factor");
  // The whole friction's factor, though the balance's κ / r reads the mesh loss's rise as well.
  EXPECT_NEAR(r.diagnosis.magnitude, 1.5, 0.05);
  EXPECT_GT(r.top.friction_factor, r.diagnosis.magnitude + 0.1);
  EXPECT_NEAR(r.top.kt_factor, 1.0, 0.03);  // the electrical side stays normal
}

TEST(PowerMonitorDetects, MotorSideWearReadsAsTheWholeFrictionsSmallerRise) {
  // The mesh loss (a fifth of the transmitted torque) stays: the joint's friction rises by less
  // than 2x, and the magnitude says by how much (the took-effect measure reads 1.66-1.68).
  const MonitoredRun r = RunMonitored(
      Exp1(Fault({{"family", "friction_increase"}, {"friction_factor", 2.0}, {"friction_terms", "motor_side"}})));
  ExpectDiagnosis(r, "friction_increase", 3, 2.0);
  EXPECT_NEAR(r.diagnosis.magnitude, 1.67, 0.1);
  EXPECT_NEAR(r.top.friction_factor, 2.0, 0.2);  // κ / r: the curve's factor
}

// The sensor's zero as the run finds it (docs/monitor.md, "The sensor's zero"): an offset
// the sensor has from the start, beyond the drift limit (1 N m), is its temperature's, not a
// drift; a drift during operation is still judged against that zero. On the six-joint arm's
// shoulder (a 0.06 N m/K zero drift is 25 K for 1.5 N m), all six joints moving.
json UrClassRun(json faults = json::array()) {
  json joints = json::object();
  const double omega[6] = {1.05, 1.57, 1.05, 1.57, 1.05, 2.09};
  for (int j = 0; j < 6; ++j) {
    joints[std::to_string(j + 1)] = {{"type", "sine_pair"}, {"amplitude_deg", 25}, {"omega_rad_s", omega[j]}};
  }
  return {{"robot", "ur-class"}, {"duration_s", 20}, {"seed", 3}, {"joints", joints}, {"faults", faults}};
}

TEST(PowerMonitorSensorZero, AnOffsetFromTheStartIsNoDrift) {
  for (double offset_Nm : {1.5, -1.5}) {
    const MonitoredRun r = RunMonitored(UrClassRun(), -1, false, 1, offset_Nm, 2);
    EXPECT_FALSE(r.diagnosis.detected) << offset_Nm << ": " << r.diagnosis.family << " on joint " << r.diagnosis.joint
                                       << " at " << r.diagnosis.detection_time_s;
  }
}

TEST(PowerMonitorSensorZero, ADriftDuringOperationIsFoundFromThatZero) {
  const MonitoredRun r = RunMonitored(UrClassRun(Fault({{"family", "torque_sensor_drift"}, {"drift_Nm_per_s", 0.5}}, 2, 8.0)),
                                      -1, false, 1, 1.5, 2);
  ASSERT_TRUE(r.diagnosis.detected);
  EXPECT_EQ(r.diagnosis.family, "torque_sensor_drift");
  EXPECT_EQ(r.diagnosis.joint, 2);
  // 1 N m past the zero at 10 s, then the slow fit's 4-s memory and the significance.
  EXPECT_GE(r.diagnosis.detection_time_s, 10.0);
  EXPECT_LT(r.diagnosis.detection_time_s, 16.0);
}

// A six-joint unit run at 80 °C against its 20 °C datasheet: its windings read 15 % more
// resistance and its magnets give 6 % less torque per ampere (the plant's NdFeB law). That is
// no K_T loss (the warm magnet's allowance, docs/monitor.md: without it, a K_T alarm on joint 2
// at 0.72 s); K_T 0.9 on the same hot unit is one.
TEST(PowerMonitorWarmMagnet, AHotUnitIsNoKtLossButAKtFaultOnItIs) {
  const MonitoredRun hot = RunMonitored(UrClassRun(), -1, false, 1, 0, 3, 80.0);
  EXPECT_GT(hot.top.resistance_factor, 1.15);
  EXPECT_LT(hot.top.kt_factor, 0.96);  // the premise: the raw K_T reading is low (without the allowance: an alarm)
  EXPECT_FALSE(hot.diagnosis.detected) << hot.diagnosis.family << " on joint " << hot.diagnosis.joint << " at "
                                       << hot.diagnosis.detection_time_s;
  const MonitoredRun fault =
      RunMonitored(UrClassRun(Fault({{"family", "kt_degradation"}, {"kt_factor", 0.9}}, 3, 8.0)), -1, false, 1, 0, 3, 80.0);
  ExpectDiagnosis(fault, "kt_degradation", 3, 8.0);
}

TEST(PowerMonitorDetects, BrakeLock) {
  const MonitoredRun r = RunMonitored(Exp1(Fault({{"family", "brake_lock"}, {"drag_fraction", 1.0}})));
  ExpectDiagnosis(r, "brake_lock", 3, 2.0);
  EXPECT_EQ(r.diagnosis.state, HealthState::kDefective);
}

TEST(PowerMonitorDetects, EveryStuckLeadWithTheStuckReading) {
  const std::map<std::string, double> rails = {{"supply", 31.5077}, {"ground", -24.4923}};
  for (const char* lead : {"supply", "ground", "open"}) {
    const MonitoredRun r = RunMonitored(Exp1(Fault({{"family", "torque_sensor_stuck"}, {"lead", lead}})));
    SCOPED_TRACE(lead);
    ExpectDiagnosis(r, "torque_sensor_stuck", 3, 2.0);
    EXPECT_EQ(r.diagnosis.magnitude_name, "stuck_reading_Nm");
    if (rails.count(lead)) {
      EXPECT_NEAR(r.diagnosis.magnitude, rails.at(lead), 1e-3);
      EXPECT_LT(r.diagnosis.detection_time_s, 2.1);
    }
  }
}

// A torque beyond the sensor's range holds the reading on its rail: saturation, which the
// monitor must not call a stuck sensor; a stuck lead on the same joint and
// motion still is one. Joint 3 lowers its link and 2 kg tool to horizontal over 3 s, where the
// load (about 6.5 N m) lies beyond a 2.3 N m sensor's top (5.81 N m with the 3.5 N m offset).
json SaturatingRun(json faults = json::array()) {
  json run = ThesisExperiment1Json();
  json robot = RobotToJson(RobotPreset("mrr-config1"));
  robot["modules"][2]["torque_sensor"]["full_scale_Nm"] = 2.3;
  run["robot"] = robot;
  run["duration_s"] = 8;
  run["joints"] = {{"3", {{"type", "min_jerk"}, {"waypoints", {{0, 60}, {1, 60}, {4, 0}, {8, 0}}}}}};
  run["faults"] = faults;
  return run;
}

TEST(PowerMonitorDetects, SaturationIsNoStuckSensorButAStuckLeadIs) {
  const MonitoredRun healthy = RunMonitored(SaturatingRun(), -1, /*record=*/true);
  ASSERT_TRUE(healthy.result.ok);
  int on_rail = 0;  // the premise: the reading sits on its top rail for seconds
  double top = -1e9;
  for (const auto& tick : healthy.rec.ticks) top = std::max(top, tick[2].signals.tau_sensor_Nm);
  for (const auto& tick : healthy.rec.ticks) on_rail += tick[2].signals.tau_sensor_Nm >= top - 1e-9 && tick[2].tau_true_Nm > top;
  EXPECT_GT(on_rail, 1000);
  EXPECT_FALSE(healthy.diagnosis.detected) << healthy.diagnosis.family;
  for (const char* lead : {"supply", "ground", "open"}) {
    SCOPED_TRACE(lead);
    const MonitoredRun r =
        RunMonitored(SaturatingRun(Fault({{"family", "torque_sensor_stuck"}, {"lead", lead}}, 3, 1.5)));
    ExpectDiagnosis(r, "torque_sensor_stuck", 3, 1.5);
  }
}

TEST(PowerMonitorDetects, PhaseToPhaseShortWithinMilliseconds) {
  const MonitoredRun r = RunMonitored(
      Exp1(Fault({{"family", "inverter_short"}, {"kind", "phase_phase"}, {"resistance_ohm", 0.1}})));
  ExpectDiagnosis(r, "inverter_short", 3, 2.0);
  EXPECT_LT(r.diagnosis.detection_time_s, 2.05);
  // Latched: the later fall of the unpowered joint does not change the diagnosis.
  EXPECT_EQ(r.output.verdicts.back().family, "inverter_short");
}

TEST(PowerMonitorDetects, NothingBeforeOnsetAndHealthyVerdictsStayEmpty) {
  const MonitoredRun r = RunMonitored(Exp1());
  EXPECT_TRUE(r.output.verdicts.empty());
  EXPECT_FALSE(r.diagnosis.detected);
}

// --- the standard output ---------------------------------------------------------------

TEST(MonitorOutput, DiagnosisTakesTheFirstAlarmAndThatJointsLastVerdict) {
  MonitorOutput out;
  auto verdict = [](double t, int joint, bool alarm, const char* family, double magnitude) {
    Verdict v;
    v.t_s = t;
    v.joint = joint;
    v.alarm = alarm;
    v.state = alarm ? HealthState::kWorn : HealthState::kHealthy;
    v.family = family;
    v.magnitude_name = alarm ? "kt_factor" : "";
    v.magnitude = magnitude;
    return v;
  };
  out.verdicts = {verdict(3.0, 3, true, "friction_increase", 1.4), verdict(3.5, 2, true, "unknown", 0),
                  verdict(4.0, 3, true, "kt_degradation", 0.72), verdict(5.0, 3, false, "", 0)};
  const Diagnosis d = Diagnose(out);
  EXPECT_TRUE(d.detected);
  EXPECT_EQ(d.detection_time_s, 3.0);
  EXPECT_EQ(d.joint, 3);
  EXPECT_EQ(d.family, "kt_degradation");
  EXPECT_EQ(d.magnitude, 0.72);
  EXPECT_EQ(ToJson(d).dump(),
            R"({"confidence":0.0,"detected":true,"detection_time_s":3.0,"isolated_family":"kt_degradation",)"
            R"("isolated_joint":3,"magnitude_estimate":0.72,"magnitude_name":"kt_factor","state":"worn"})");
  EXPECT_EQ(ToJson(Diagnose(MonitorOutput())).dump(),
            R"({"confidence":null,"detected":false,"detection_time_s":null,"isolated_family":null,)"
            R"("isolated_joint":null,"magnitude_estimate":null,"magnitude_name":null,"state":"healthy"})");
}

// --- configuration ---------------------------------------------------------------------

TEST(MonitorConfigJson, RoundTripsAndRejectsUnknownKeysWithTheirPointer) {
  MonitorConfig c;
  c.kt_factor.worn = 0.95;
  c.debounce_s = 0.7;
  const MonitorConfig back = MonitorConfigFromJson(MonitorConfigToJson(c), "", "m.json");
  EXPECT_EQ(MonitorConfigToJson(back), MonitorConfigToJson(c));

  const InputError e = ErrorOf([] { MonitorConfigFromJson(json{{"kt_factr", 1}}, "/monitor", "c.json"); });
  EXPECT_EQ(e.source(), "c.json");
  EXPECT_EQ(e.pointer(), "/monitor/kt_factr");
  EXPECT_THAT(e.message(), HasSubstr("unknown key"));
  const InputError limits =
      ErrorOf([] { MonitorConfigFromJson(json{{"kt_factor", {{"worn", 0.9}, {"wron", 1}}}}, "/monitor", "c.json"); });
  EXPECT_EQ(limits.pointer(), "/monitor/kt_factor/wron");
}

TEST(MonitorConfigJson, OutOfRangeValuesNameFieldAndValue) {
  const InputError e =
      ErrorOf([] { MonitorConfigFromJson(json{{"kt_factor", {{"worn", 0.8}, {"defective", 0.9}}}}, "", "m.json"); });
  EXPECT_EQ(e.pointer(), "/kt_factor/defective");
  EXPECT_THAT(e.message(), HasSubstr("0.9"));
  const InputError neg = ErrorOf([] { MonitorConfigFromJson(json{{"debounce_s", -1}}, "", "m.json"); });
  EXPECT_EQ(neg.pointer(), "/debounce_s");
  EXPECT_THAT(neg.message(), HasSubstr("-1"));
  const InputError type = ErrorOf([] { MonitorConfigFromJson(json{{"mechanical_windows", "3"}}, "", "m.json"); });
  EXPECT_EQ(type.pointer(), "/mechanical_windows");
}

TEST(MonitorConfigJson, RunFilesTakeThresholdsInlineOrFromAFile) {
  testing_support::ScratchDir dir("monitor");
  dir.Write("strict.json", R"({"kt_factor": {"worn": 0.97, "defective": 0.8}})");
  InputContext context;
  context.source = (dir.path() / "run.json").string();
  context.base_dir = dir.path().string();
  json run = ThesisExperiment1Json();
  run["monitor"] = "strict.json";
  EXPECT_EQ(RunConfigFromJson(run, "", context).monitor.settings["kt_factor"]["worn"], 0.97);
  run["monitor"] = {{"debounce_s", 1.5}};
  EXPECT_EQ(RunConfigFromJson(run, "", context).monitor.settings["debounce_s"], 1.5);
  run["monitor"] = {{"type", "power_efficiency"}, {"debounce_s", 1.5}};
  EXPECT_EQ(RunConfigFromJson(run, "", context).monitor.type, "power_efficiency");
  EXPECT_EQ(RunConfigFromJson(run, "", context).monitor.settings["debounce_s"], 1.5);
  run["monitor"] = {{"debounce_s", "x"}};
  const InputError e = ErrorOf([&] { RunConfigFromJson(run, "", context); });
  EXPECT_EQ(e.pointer(), "/monitor/debounce_s");
  EXPECT_EQ(e.source(), context.source);
  run["monitor"] = "missing.json";
  EXPECT_THAT(ErrorOf([&] { RunConfigFromJson(run, "", context); }).what(), HasSubstr("missing.json"));
}

// --- commissioning ------------------------------------------------------------------------

// A unit that is not its datasheet: stronger magnet, more friction, a lower mesh loss, more
// quiescent draw.
RobotConfig OffDatasheetUnit() {
  RobotConfig robot = RobotPreset("mrr-config1");
  for (ModuleParams& m : robot.modules) {
    m.motor.kt_Nm_per_A *= 1.05;
    m.friction.viscous_Nm_s_per_rad *= 1.25;
    m.friction.coulomb_Nm *= 1.25;
    m.friction.static_Nm *= 1.25;
    m.drive.mesh_loss_fraction = 0.20;
    m.inverter.quiescent_power_W = 2.6;
  }

  return robot;
}

// Every joint moving both ways at several speeds.
json MovingAllJoints(double duration_s) {
  return {{"duration_s", duration_s},
          {"joints",
           {{"1", {{"type", "sine_pair"}, {"amplitude_deg", 30}, {"omega_rad_s", 1.1}}},
            {"2", {{"type", "cosine_ramp"}, {"amplitude_deg", 25}, {"period_s", 4}}},
            {"3", {{"type", "sine_pair"}, {"amplitude_deg", 25}, {"omega_rad_s", 1.2732}}}}}};
}

// Simulates `run_json` on `robot`, giving `on_tick` what a monitor may read at every tick.
template <typename OnTick>
void Simulated(const RobotConfig& robot, const json& run_json, uint64_t seed, OnTick on_tick) {
  InputContext context;
  context.source = "<test>";
  RunConfig run = RunConfigFromJson(run_json, "", context);
  run.robot = robot;
  run.seed = seed;
  const ArmModel model(robot);
  std::vector<JointSignals> s;
  const RunResult r = Simulate(model, MakeRunSpec(run), [&](const Tick& tick) {
    s.clear();
    for (const JointTick& jt : *tick.joints) s.push_back(jt.signals);
    on_tick(tick.t_s, s);
  });
  ASSERT_TRUE(r.ok) << r.failure_reason;
}

// `nominal` commissioned on `robot` running `run_json`, streamed tick by tick as a campaign does.
PowerMonitorModel Commissioned(const PowerMonitorModel& nominal, const RobotConfig& robot, const json& run_json,
                               uint64_t seed) {
  PowerMonitorCommissioning fit(nominal, nominal.control_dt_s);
  Simulated(robot, run_json, seed, [&](double, const std::vector<JointSignals>& s) { fit.Tick(s); });
  return fit.End();
}

// The friction factor the fast balance fit holds at the end of a healthy run of `robot`.
double HealthyFrictionFactor(const RobotConfig& robot, const PowerMonitorModel& monitor_model, int joint, uint64_t seed) {
  PowerEfficiencyMonitor monitor(monitor_model);
  Simulated(robot, MovingAllJoints(8), seed,
            [&](double t_s, const std::vector<JointSignals>& s) { monitor.Observe(t_s, s); });
  // against the commissioned curve (not the run's own friction reference)
  return monitor.estimates(joint).friction_factor * monitor.estimates(joint).friction_reference;
}

TEST(Commissioning, LearnsTheUnitFromItsHealthySignals) {
  const RobotConfig unit = OffDatasheetUnit();
  const PowerMonitorModel nominal = MakePowerMonitorModel(RobotPreset("mrr-config1"), MonitorConfig());
  const PowerMonitorModel learned = Commissioned(nominal, unit, MovingAllJoints(16), 99);
  for (int j = 0; j < 3; ++j) {
    const JointKnowledge& k = learned.joints[j];
    EXPECT_TRUE(k.commissioned) << "joint " << j + 1;
    // Electrical: 30 % more quiescent draw, 5 % more back-EMF per perceived rotor power.
    EXPECT_NEAR(k.electrical.quiescent_W, 2.6, 0.15) << "joint " << j + 1;
    EXPECT_NEAR(k.electrical.rotor_gain, 1.05, 0.02) << "joint " << j + 1;
    // Mechanical: torque per perceived torque 1.05, friction 1.25 x the datasheet's.
    const MechanicalCalibration& m = k.mechanical;
    const MechanicalCalibration& m0 = nominal.joints[j].mechanical;
    EXPECT_NEAR(m.torque_gain, 1.05, 0.03) << "joint " << j + 1;
    const double f = m.FrictionNm(0.5) / m0.FrictionNm(0.5);
    RecordProperty("friction_ratio_j" + std::to_string(j + 1), std::to_string(f));
    EXPECT_NEAR(f, 1.25, 0.08) << "joint " << j + 1;
  }
  for (const JointKnowledge& k : learned.joints) EXPECT_NEAR(k.mechanical.sensor_offset_Nm, 0.0, 0.1);
}

// A strain-wave gear loses more, or less, of the transmitted torque when the link drives the
// motor than when the motor drives the link (load friction by the direction of power flow).
// Commissioning reads the difference, μ_x, from the signals, whichever way it goes; the
// datasheet's is 0.
RobotConfig UnitWithLoadFriction(double driving, double backdriven) {
  RobotConfig robot = RobotPreset("mrr-config1");
  for (ModuleParams& m : robot.modules) {
    m.gearbox.present = true;
    m.gearbox.load_friction_driving = driving;
    m.gearbox.load_friction_backdriven = backdriven;
  }
  return robot;
}

TEST(Commissioning, LearnsWhichWayTheGearsLoadFrictionIsLarger) {
  const PowerMonitorModel nominal = MakePowerMonitorModel(RobotPreset("mrr-config1"), MonitorConfig());
  for (const JointKnowledge& k : nominal.joints) EXPECT_EQ(k.mechanical.mesh_backdriven_extra, 0.0);
  const PowerMonitorModel less_back = Commissioned(nominal, UnitWithLoadFriction(0.10, 0.02), MovingAllJoints(16), 99);
  const PowerMonitorModel more_back = Commissioned(nominal, UnitWithLoadFriction(0.02, 0.10), MovingAllJoints(16), 99);
  for (int j = 1; j < 3; ++j) {  // the base (j = 0) has a pure inertia load: little torque back-driven
    SCOPED_TRACE(j + 1);
    const double less = less_back.joints[j].mechanical.mesh_backdriven_extra;
    const double more = more_back.joints[j].mechanical.mesh_backdriven_extra;
    RecordProperty("mesh_backdriven_extra_less_j" + std::to_string(j + 1), std::to_string(less));
    RecordProperty("mesh_backdriven_extra_more_j" + std::to_string(j + 1), std::to_string(more));
    EXPECT_LT(less, -0.02);
    EXPECT_GT(more, 0.02);
    EXPECT_NEAR(more - less, 0.16, 0.08);  // the truth: +0.08 and -0.08
  }
}

TEST(Commissioning, HealthyUnitReadsHealthyOnlyAfterCommissioning) {
  const RobotConfig unit = OffDatasheetUnit();
  const PowerMonitorModel nominal = MakePowerMonitorModel(RobotPreset("mrr-config1"), MonitorConfig());
  const PowerMonitorModel learned = Commissioned(nominal, unit, MovingAllJoints(16), 99);
  for (int j = 0; j < 3; ++j) {
    const double before = HealthyFrictionFactor(unit, nominal, j, 5);
    const double after = HealthyFrictionFactor(unit, learned, j, 5);
    RecordProperty("friction_factor_nominal_j" + std::to_string(j + 1), std::to_string(before));
    RecordProperty("friction_factor_commissioned_j" + std::to_string(j + 1), std::to_string(after));
    EXPECT_GT(std::fabs(before - 1.0), 0.1) << "joint " << j + 1 << ": the datasheet should not fit this unit";
    EXPECT_NEAR(after, 1.0, 0.05) << "joint " << j + 1;
  }
}

TEST(WidenedForTolerances, NoToleranceNoChangeAndEachToleranceWidensItsDetectors) {
  const RobotConfig robot = RobotPreset("mrr-config1");
  const MonitorConfig base;
  const MonitorConfig same = WidenedForTolerances(base, StatedTolerances(), robot);
  // At 20 °C with nothing stated only the self-heating margin remains.
  EXPECT_LT(same.kt_factor.worn, base.kt_factor.worn);
  EXPECT_GT(same.kt_factor.worn, base.kt_factor.worn - 0.02);
  StatedTolerances kt;
  kt.kt = 0.05;
  const MonitorConfig wide = WidenedForTolerances(base, kt, robot);
  EXPECT_NEAR(same.kt_factor.worn - wide.kt_factor.worn, 0.05, 1e-12);
  EXPECT_GT(wide.friction_factor.worn, same.friction_factor.worn);  // a torque-scale error reaches friction
  EXPECT_EQ(wide.resistance_factor.worn, same.resistance_factor.worn);
  StatedTolerances offset;
  offset.torque_sensor_offset_Nm = 0.5;
  EXPECT_NEAR(WidenedForTolerances(base, offset, robot).sensor_drift_Nm.worn - same.sensor_drift_Nm.worn, 0.5, 1e-12);
  // A constant-power error is a parameter of the electrical fit: it widens its uncertainty
  // (0.3 x 2 W of quiescent draw), not the K_T or resistance limits.
  StatedTolerances quiescent;
  quiescent.quiescent_power = 0.3;
  const MonitorConfig q = WidenedForTolerances(base, quiescent, robot);
  EXPECT_NEAR(q.constant_power_uncertainty_W, 0.6, 1e-9);
  EXPECT_EQ(q.resistance_factor.worn, same.resistance_factor.worn);
  Validate(q, "", "<test>");  // still a valid config
}

TEST(Commissioning, TooFewTicksOrAnotherRobotsSignalsLeaveTheDatasheet) {
  const PowerMonitorModel nominal = MakePowerMonitorModel(RobotPreset("mrr-config1"), MonitorConfig());
  PowerMonitorCommissioning empty(nominal, nominal.control_dt_s);
  for (const JointKnowledge& k : empty.End().joints) EXPECT_FALSE(k.commissioned);
  // Two joints' signals for a three-joint robot, however many ticks.
  PowerMonitorCommissioning foreign(nominal, nominal.control_dt_s);
  long ticks = 0;
  Simulated(RobotPreset("mrr-config1"), MovingAllJoints(2), 7, [&](double, const std::vector<JointSignals>& s) {
    foreign.Tick(std::vector<JointSignals>(s.begin(), s.begin() + 2));
    ++ticks;
  });
  EXPECT_GT(ticks, 1000);
  for (const JointKnowledge& k : foreign.End().joints) EXPECT_FALSE(k.commissioned);
}

// The fit is streamed: End gives the model of the ticks so far, and a unit commissioned on the
// first half of a motion is fitted, just on less.
TEST(Commissioning, EndGivesTheFitOfTheTicksSoFar) {
  const RobotConfig unit = OffDatasheetUnit();
  const PowerMonitorModel nominal = MakePowerMonitorModel(RobotPreset("mrr-config1"), MonitorConfig());
  PowerMonitorCommissioning fit(nominal, nominal.control_dt_s);
  PowerMonitorModel half;
  Simulated(unit, MovingAllJoints(16), 99, [&](double t_s, const std::vector<JointSignals>& s) {
    fit.Tick(s);
    if (half.joints.empty() && t_s >= 8.0) half = fit.End();
  });
  const PowerMonitorModel whole = fit.End();
  RecordProperty("ticks", std::to_string(fit.ticks()));
  RecordProperty("balance_rows", std::to_string(fit.balance_rows()));
  EXPECT_GT(fit.ticks(), 7000);  // 16 s at 2 ms
  EXPECT_GT(fit.balance_rows(), 3 * 5000);  // most joint-ticks moving one way: in the balance's sums
  ASSERT_EQ(half.joints.size(), 3u);
  for (int j = 0; j < 3; ++j) {
    EXPECT_TRUE(half.joints[j].commissioned) << "joint " << j + 1;
    EXPECT_NE(half.joints[j].electrical.quiescent_W, whole.joints[j].electrical.quiescent_W) << "joint " << j + 1;
    EXPECT_NEAR(half.joints[j].electrical.rotor_gain, 1.05, 0.03) << "joint " << j + 1;
  }
}

// ur-class on the industrial drives with their gearbox group (gearbox node, Vogel lubricant law,
// load friction, sensor drift: docs/assumptions.md), all joints on the repeating sine pairs.
json UrClassThermalRun(json faults, double duration_s) {
  json run = UrClassRun(faults);
  json drives = json::object();
  for (const char* j : {"shoulder_pan", "shoulder_lift", "elbow"}) drives[j] = "industrial-large-thermal";
  for (const char* j : {"wrist_1", "wrist_2", "wrist_3"}) drives[j] = "industrial-small-thermal";
  run["robot"] = {{"name", "ur-class-thermal"},
                  {"urdf", std::string(ARMFAULT_SOURCE_DIR) + "/campaigns/files/robots/ur-class.urdf"},
                  {"drives", drives}};
  run["duration_s"] = duration_s;
  return run;
}

// A cold morning: the unit, commissioned at 20 degC, starts at 5 degC, its lubricant thick
// (the plant's law: viscous friction 1.39x, Coulomb 1.18x). That is no wear (the cold
// allowance, docs/monitor.md "The friction the run finds"); friction 1.5x on the same cold unit
// from the start is. 0 degC: AColdMagnetDoesNotWarmTheWinding.
TEST(PowerMonitorLubricant, AColdStartIsNoWearButWearOnItIs) {
  const MonitoredRun cold =
      RunMonitored(UrClassThermalRun(json::array(), 20), -1, false, 1, 0, 3, 5.0, ThermalStart::kCold, true);
  ASSERT_TRUE(cold.result.ok);
  // the premise: the cold lubricant's friction against the calibration (1.14; 1.2-1.3 while the
  // fast fit held the calibrated zero and the cold sensor's offset swung it)
  EXPECT_GT(cold.top.friction_factor * cold.top.friction_reference, 1.1);
  EXPECT_GT(cold.top.friction_reference, 1.05);  // an allowance
  EXPECT_FALSE(cold.diagnosis.detected) << cold.diagnosis.family << " on joint " << cold.diagnosis.joint << " at "
                                        << cold.diagnosis.detection_time_s;
  const MonitoredRun worn = RunMonitored(
      UrClassThermalRun(Fault({{"family", "friction_increase"}, {"friction_factor", 1.5}}, 3, 0.0), 20), -1, false, 1, 0,
      3, 5.0, ThermalStart::kCold, true);
  ExpectDiagnosis(worn, "friction_increase", 3, 0.0);
}

// A unit commissioned at 20 degC started at 0 degC: its windings hold 7.9 % less resistance
// and its magnets give more torque per ampere (the plant: 0.1 %/K, so 2 %). With K_T held at
// its commissioned value the cold magnet's extra rotor power passes for copper loss and the
// winding reads warmer than it is (joint 2: +9 % where it is -8 %); the electrical fit lets K_T
// rise as far as a magnet as cold as the winding reads could (docs/monitor.md). Every winding
// then reads 3-8 % cold, and the cold allowance holds the thick lubricant (at the previous
// stop: a friction alarm on joint 2 at 5.2 s).
TEST(PowerMonitorLubricant, AColdMagnetDoesNotWarmTheWinding) {
  const MonitoredRun cold =
      RunMonitored(UrClassThermalRun(json::array(), 20), -1, false, 1, 0, 3, 0.0, ThermalStart::kCold, true);
  ASSERT_TRUE(cold.result.ok);
  for (size_t j = 0; j < cold.all.size(); ++j) {
    SCOPED_TRACE(j + 1);
    EXPECT_LT(cold.all[j].resistance_factor, 0.97);
    EXPECT_GT(cold.all[j].resistance_factor, 0.9);
    EXPECT_GT(cold.all[j].kt_factor, 1.0);  // the cold magnet, within its bound
    EXPECT_LE(cold.all[j].kt_factor, 1.0 + 0.12 / 0.393 * (1.0 - cold.all[j].resistance_factor) + 1e-12);
    EXPECT_GT(cold.all[j].friction_reference, 1.1);  // 14 K of cold read at least (20 K: 1.25)
  }
  EXPECT_FALSE(cold.diagnosis.detected) << cold.diagnosis.family << " on joint " << cold.diagnosis.joint << " at "
                                        << cold.diagnosis.detection_time_s;
}

// The arm's readings are taken once per tick, before any joint's estimators move, so the
// order in which the joints are updated changes nothing: a cold start at 3 degC (the arm's
// cold readings in play) with wear on the wrist, every joint updated last joint first, gives
// the same verdicts and windows to the bit.
TEST(PowerMonitorOrder, UpdatingTheJointsInReverseChangesNoVerdict) {
  const json run = UrClassThermalRun(Fault({{"family", "friction_increase"}, {"friction_factor", 1.5}}, 4, 8.0), 16);
  const MonitoredRun forward = RunMonitored(run, -1, false, 1, 0, 3, 3.0, ThermalStart::kCold, true, false);
  const MonitoredRun reverse = RunMonitored(run, -1, false, 1, 0, 3, 3.0, ThermalStart::kCold, true, true);
  ASSERT_TRUE(forward.result.ok);
  ExpectDiagnosis(forward, "friction_increase", 4, 8.0);
  EXPECT_EQ(ToJson(forward.output).dump(), ToJson(reverse.output).dump());
  EXPECT_GT(forward.output.windows.size(), 30u);
  for (size_t j = 0; j < forward.all.size(); ++j) {
    EXPECT_EQ(forward.all[j].friction_reference, reverse.all[j].friction_reference) << "joint " << j + 1;
  }
}

// The sequential decision (docs/monitor.md, "Sequential decision") on the same run: its CUSUMs
// find the wear on the wrist after its onset, and the joints' update order changes nothing.
TEST(PowerMonitorOrder, TheSequentialDecisionIsTheSameInReverseAndFindsTheWear) {
  json run = UrClassThermalRun(Fault({{"family", "friction_increase"}, {"friction_factor", 1.5}}, 4, 8.0), 30);
  run["monitor"] = {{"decision", "sequential"}};
  const MonitoredRun forward = RunMonitored(run, -1, false, 1, 0, 3, 3.0, ThermalStart::kCold, true, false);
  const MonitoredRun reverse = RunMonitored(run, -1, false, 1, 0, 3, 3.0, ThermalStart::kCold, true, true);
  ASSERT_TRUE(forward.result.ok);
  ExpectDiagnosis(forward, "friction_increase", 4, 8.0, 22.0);
  EXPECT_EQ(ToJson(forward.output).dump(), ToJson(reverse.output).dump());
}

// A warm start at 40 degC: the gear's lubricant is thin and the wrist's friction under its
// calibrated curve, so that friction 1.5x stays under the limit against the calibration. The
// reference follows the top of the fast factor's swing down once a minute of motion has shown
// it, and the same wear two minutes in is found against it.
TEST(PowerMonitorLubricant, AWarmGearsFrictionIsTheReferenceForWear) {
  const MonitoredRun warm =
      RunMonitored(UrClassThermalRun(json::array(), 150), -1, false, 1, 0, 3, 40.0, ThermalStart::kWarm, true);
  ASSERT_TRUE(warm.result.ok);
  EXPECT_LT(warm.all.at(5).friction_reference, 0.9);
  EXPECT_FALSE(warm.diagnosis.detected) << warm.diagnosis.family << " on joint " << warm.diagnosis.joint << " at "
                                        << warm.diagnosis.detection_time_s;
  const MonitoredRun worn =
      RunMonitored(UrClassThermalRun(Fault({{"family", "friction_increase"}, {"friction_factor", 1.5}}, 6, 120.0), 150),
                   -1, false, 1, 0, 3, 40.0, ThermalStart::kWarm, true);
  ExpectDiagnosis(worn, "friction_increase", 6, 120.0);
  // the premise: against the calibration the worn wrist is under the 1.3 limit
  const PowerEfficiencyMonitor::Estimates& wrist = worn.all.at(5);
  EXPECT_LT(wrist.friction_factor * wrist.friction_reference, 1.3);
  EXPECT_GT(wrist.friction_factor, 1.3);
}

// Wear present from a warm start at 40 degC: the thin lubricant hides friction 1.5x under the
// calibrated curve. Every winding that reads warm says the gear is warm too, and a warm gear's
// friction is at most the warm floor (docs/monitor.md, "The friction the run finds"), but at
// the gentlest thinning the floor allows (0.92 here) the worn wrist reads 1.21 of it, under the
// limit. It was found at 8-15 s while the fast fit held the sensor's calibrated zero: the warm
// sensor's offset swung the fit with the direction of motion, and the swing's top crossed the
// limit. With the zero the run finds removed, the wrist reads the same both ways, and this
// wear is what the monitor cannot tell from a gear whose lubricant thins less (a limit,
// docs/monitor.md, "The zero removed from the fast fit").
TEST(PowerMonitorLubricant, WearFromAWarmStartIsHiddenByTheThinLubricant) {
  const MonitoredRun worn =
      RunMonitored(UrClassThermalRun(Fault({{"family", "friction_increase"}, {"friction_factor", 1.5}}, 6, 0.0), 30),
                   -1, false, 1, 0, 3, 40.0, ThermalStart::kWarm, true);
  const PowerEfficiencyMonitor::Estimates& wrist = worn.all.at(5);
  EXPECT_LT(wrist.friction_reference, 0.95);  // the floor
  EXPECT_GT(wrist.friction_factor, 1.1);      // the wear shows against it
  EXPECT_LT(wrist.friction_factor, 1.3);      // but under the limit
  EXPECT_LT(wrist.friction_factor * wrist.friction_reference, 1.3);
  EXPECT_FALSE(worn.diagnosis.detected) << worn.diagnosis.family << " on joint " << worn.diagnosis.joint << " at "
                                        << worn.diagnosis.detection_time_s;
}

// A drive whose friction does not fall when warm (the plain drives: no lubricant law) is held
// to no floor its peers do not reach: at 80 degC every winding of the ur-class arm reads warm,
// which alone would lower the reference to the warm floor (0.87-0.92) and let joint 2 alarm at
// 6.5 s, but the arm's gears show their calibrated friction, so the reference stays at 1.
TEST(PowerMonitorLubricant, AWarmFloorIsNoLowerThanTheArmsGearsShow) {
  const MonitoredRun hot = RunMonitored(UrClassRun(), -1, false, 1, 0, 3, 80.0);
  EXPECT_FALSE(hot.diagnosis.detected) << hot.diagnosis.family << " on joint " << hot.diagnosis.joint << " at "
                                       << hot.diagnosis.detection_time_s;
  int warm_windings = 0;
  for (size_t j = 0; j < hot.all.size(); ++j) {
    SCOPED_TRACE(j + 1);
    if (hot.all[j].resistance_factor > 1.02) ++warm_windings;  // 5 K over the commissioning: W < 1
    EXPECT_GE(hot.all[j].friction_reference, 0.99);
  }
  EXPECT_GE(warm_windings, 3);  // the premise: the windings say warm
}

}  // namespace
}  // namespace armfault

namespace armfault {
namespace {

// The run of UrClassThermalRun judged with the arm's friction model (friction_model.h).
json WithArmModel(json run) {
  run["monitor"] = {{"friction_reference", "arm_model"}};
  return run;
}

// The arm's friction model is computed once per tick from every joint's state after the last
// tick: updating the joints last joint first gives the same verdicts and windows to the bit.
TEST(PowerMonitorArmModel, UpdatingTheJointsInReverseChangesNoVerdict) {
  const json run =
      WithArmModel(UrClassThermalRun(Fault({{"family", "friction_increase"}, {"friction_factor", 1.5}}, 4, 8.0), 16));
  const MonitoredRun forward = RunMonitored(run, -1, false, 1, 0, 3, 3.0, ThermalStart::kCold, true, false);
  const MonitoredRun reverse = RunMonitored(run, -1, false, 1, 0, 3, 3.0, ThermalStart::kCold, true, true);
  ASSERT_TRUE(forward.result.ok);
  EXPECT_EQ(ToJson(forward.output).dump(), ToJson(reverse.output).dump());
  for (size_t j = 0; j < forward.all.size(); ++j) {
    EXPECT_EQ(forward.all[j].friction_reference, reverse.all[j].friction_reference) << "joint " << j + 1;
    EXPECT_EQ(forward.all[j].friction_factor_se, reverse.all[j].friction_factor_se) << "joint " << j + 1;
  }
}

// A cold morning (5 degC against a commissioning at 20): the arm's gears teach the model their
// thick lubricant, so the cold is no wear; wear on the elbow from the start is, against what
// the other five gears show.
TEST(PowerMonitorArmModel, AColdStartIsNoWearButWearOnItIs) {
  const MonitoredRun cold =
      RunMonitored(WithArmModel(UrClassThermalRun(json::array(), 20)), -1, false, 1, 0, 3, 5.0, ThermalStart::kCold, true);
  ASSERT_TRUE(cold.result.ok);
  EXPECT_GT(cold.top.friction_reference, 1.05);  // the cold the arm shows
  EXPECT_FALSE(cold.diagnosis.detected) << cold.diagnosis.family << " on joint " << cold.diagnosis.joint << " at "
                                        << cold.diagnosis.detection_time_s;
  const MonitoredRun worn = RunMonitored(
      WithArmModel(UrClassThermalRun(Fault({{"family", "friction_increase"}, {"friction_factor", 1.5}}, 3, 0.0), 20)),
      -1, false, 1, 0, 3, 5.0, ThermalStart::kCold, true);
  // found once the windings' readings have converged (10 s of copper loss) and the other gears
  // have shown what the cold does (11.4 s; the rules: under 4 s, on an allowance whatever the
  // lubricant)
  ExpectDiagnosis(worn, "friction_increase", 3, 0.0, 15.0);
}

// Wear present from a warm start (40 degC) on the wrist, which the rules take for a gear that
// thins less (PowerMonitorLubricant.WearFromAWarmStartIsHiddenByTheThinLubricant): the model
// judges the wrist against the thinning its arm-mates teach, and the wrist's own blocks are not
// in its reference. A limit too: the others teach a 7 % thinning at the wrist's temperature,
// where its gear thins about 25 %, so the wear reads 1.19 of the reference, under the limit
// 1.3 (docs/monitor.md, "The arm's friction model", figures).
TEST(PowerMonitorArmModel, WearFromAWarmStartShowsAgainstTheArmsThinning) {
  const MonitoredRun worn = RunMonitored(
      WithArmModel(UrClassThermalRun(Fault({{"family", "friction_increase"}, {"friction_factor", 1.5}}, 6, 0.0), 60)),
      -1, false, 1, 0, 3, 40.0, ThermalStart::kWarm, true);
  const PowerEfficiencyMonitor::Estimates& wrist = worn.all.at(5);
  EXPECT_LT(wrist.friction_reference, 0.95);  // the arm's thinning
  EXPECT_GT(wrist.friction_factor, 1.1);      // the wear shows against it
  EXPECT_LT(wrist.friction_factor, 1.3);      // but under the limit
  EXPECT_FALSE(worn.diagnosis.detected) << worn.diagnosis.family << " on joint " << worn.diagnosis.joint << " at "
                                        << worn.diagnosis.detection_time_s;
}

}  // namespace
}  // namespace armfault
