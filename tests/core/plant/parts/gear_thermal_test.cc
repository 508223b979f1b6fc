// The confounders' plant: the gearbox thermal node, friction against the lubricant's temperature
// (Vogel), load- and direction-dependent gear friction, the torque sensor's thermal drift,
// cold and warm starts and repeating work cycles. Each law against its equation, then in the
// simulation; the energy balance with all of it on; a neutral gearbox group changes nothing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "core/plant/drive/friction.h"
#include "core/plant/parts/gear_thermal.h"
#include "core/plant/parts/load_friction.h"
#include "core/plant/simulation.h"
#include "core/plant/motion/trajectory.h"
#include "core/run_config.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using testing::HasSubstr;
using testing_support::ErrorOf;
using testing_support::Recording;

GearboxParams Vogel() {
  GearboxParams g;
  g.present = true;
  g.vogel_B_K = 277;
  g.vogel_C_C = -100;
  g.reference_C = 20;
  return g;
}

// ---------------------------------------------------------------- the laws

TEST(GearThermalLaw, LubricantFactorIsVogelsLawAndOneAtTheReference) {
  const GearboxParams g = Vogel();
  EXPECT_DOUBLE_EQ(LubricantFactor(g, 20), 1.0);
  EXPECT_NEAR(LubricantFactor(g, -10), std::exp(277.0 / 90 - 277.0 / 120), 1e-12);
  EXPECT_NEAR(LubricantFactor(g, 40), std::exp(277.0 / 140 - 277.0 / 120), 1e-12);
  // The chosen values: about 3x from -10 to 40 C (docs/assumptions.md).
  EXPECT_NEAR(LubricantFactor(g, -10) / LubricantFactor(g, 40), 3.0, 0.01);
  GearboxParams off = g;
  off.vogel_B_K = 0;
  EXPECT_EQ(LubricantFactor(off, -30), 1.0);
}

TEST(GearThermalLaw, GearNodeSettlesAtAmbientPlusRTimesP) {
  GearboxParams g;
  g.present = true;
  g.thermal_resistance_K_per_W = 2.5;
  g.thermal_time_constant_s = 10;
  ThermalNodes n{25, 25};
  for (int k = 0; k < 200000; ++k) StepThermalNodes(3.0, 50, g, 25, 0.0, 4.0, 1e-3, &n);  // 20 time constants
  EXPECT_NEAR(n.gear_C, 25 + 2.5 * 4.0, 1e-6);
  EXPECT_NEAR(n.winding_C, 25, 1e-9);  // no coupling, no copper loss
  const ThermalNodes steady = SteadyThermalNodes(3.0, g, 25, 0.0, 4.0);
  EXPECT_DOUBLE_EQ(steady.gear_C, 35);
}

TEST(GearThermalLaw, CoupledNodesSettleAtTheNetworksSolutionAndConserveHeat) {
  GearboxParams g;
  g.present = true;
  g.thermal_resistance_K_per_W = 1.2;
  g.thermal_time_constant_s = 30;
  g.winding_coupling_W_per_K = 1.5;
  const double rw = 1.5, pc = 10, pf = 15, amb = 5;
  ThermalNodes n{amb, amb};
  for (int k = 0; k < 1000000; ++k) StepThermalNodes(rw, 20, g, amb, pc, pf, 1e-3, &n);
  const ThermalNodes s = SteadyThermalNodes(rw, g, amb, pc, pf);
  EXPECT_NEAR(n.winding_C, s.winding_C, 1e-6);
  EXPECT_NEAR(n.gear_C, s.gear_C, 1e-6);
  // All the heat leaves to ambient through the two resistances.
  EXPECT_NEAR((s.winding_C - amb) / rw + (s.gear_C - amb) / g.thermal_resistance_K_per_W, pc + pf, 1e-9);
  // The warm start is that steady state at the stated duty; at ambient without a gearbox group.
  g.warm_copper_loss_W = pc;
  g.warm_friction_loss_W = pf;
  EXPECT_DOUBLE_EQ(WarmSteadyState(rw, g, amb).gear_C, s.gear_C);
  g.present = false;
  EXPECT_EQ(WarmSteadyState(rw, g, amb).gear_C, amb);
  EXPECT_EQ(WarmSteadyState(rw, g, amb).winding_C, amb);
}

TEST(GearThermalLaw, SensorDriftFollowsTheGearTemperatureStep) {
  GearboxParams g = Vogel();
  g.sensor_offset_Nm_per_K = 0.05;
  g.sensor_gain_per_K = 1e-4;
  EXPECT_DOUBLE_EQ(DriftedSensorInputNm(g, 20, 0.01, 0.2, 100), 1.01 * 100 + 0.2);  // none at the reference
  // A 15 K step: offset 0.75 N m, gain 0.15 %.
  EXPECT_NEAR(DriftedSensorInputNm(g, 35, 0.01, 0.2, 100) - DriftedSensorInputNm(g, 20, 0.01, 0.2, 100),
              0.05 * 15 + 1e-4 * 15 * 100, 1e-12);
}

TEST(LoadFrictionLaw, GrowsWithTorqueAndDependsOnThePowerFlow) {
  GearboxParams g;
  g.present = true;
  g.load_friction_driving = 0.05;
  g.load_friction_backdriven = 0.12;
  EXPECT_EQ(PowerFlowOf(10, 1), PowerFlow::kDriving);
  EXPECT_EQ(PowerFlowOf(-10, -1), PowerFlow::kDriving);
  EXPECT_EQ(PowerFlowOf(10, -1), PowerFlow::kBackDriven);
  EXPECT_EQ(PowerFlowOf(10, 0), PowerFlow::kDriving);  // holding
  EXPECT_DOUBLE_EQ(LoadFrictionNm(g, 50, 1, 100), 0.05 * 50 / 100);
  EXPECT_DOUBLE_EQ(LoadFrictionNm(g, -50, 1, 100), 0.12 * 50 / 100);
  EXPECT_DOUBLE_EQ(LoadFrictionNm(g, 100, 1, 100), 2 * LoadFrictionNm(g, 50, 1, 100));
  g.present = false;
  EXPECT_EQ(LoadFrictionNm(g, 50, 1, 100), 0.0);
}

// ---------------------------------------------------------------- in the simulation

// One link swinging in a horizontal plane (no gravity load): friction only, no mesh loss.
RobotConfig FlatPendulum() {
  RobotConfig robot = RobotPreset("pendulum");
  robot.gravity_m_s2 = 0;
  ModuleParams& m = robot.modules[0];
  m.drive.mesh_loss_fraction = 0;
  m.torque_sensor.noise_Nm = 0;
  m.inverter.supply_current_noise_A = 0;
  m.gearbox = Vogel();
  m.gearbox.thermal_time_constant_s = 1e6;  // the node stays at ambient within the run
  return robot;
}

const nlohmann::json kSwing = {{"type", "sine_pair"}, {"amplitude_deg", 40}, {"omega_rad_s", 2.0}};

Recording RunJoint(const RobotConfig& robot, double ambient_C, double duration_s, const nlohmann::json& motion = kSwing,
              ThermalStart start = ThermalStart::kCold, RunResult* result = nullptr) {
  const ArmModel model(robot);
  RunSpec spec;
  spec.duration_s = duration_s;
  spec.ambient_C = ambient_C;
  spec.start = start;
  spec.joints.resize(robot.modules.size());
  spec.joints[0].trajectory = MakeTrajectory(motion, "", InputContext{});
  Recording rec;
  const RunResult r = Simulate(model, spec, rec.Observer());
  EXPECT_TRUE(r.ok) << r.failure_reason;
  if (result) *result = r;
  return rec;
}

// The friction power the law predicts at the tick's link velocity and gear temperature.
double PredictedFrictionW(const ModuleParams& m, const JointTick& j) {
  const double f = LubricantFactor(m.gearbox, j.gear_temp_C);
  const double torque = ViscousFrictionNm(m.friction, f, j.qd_rad_s) +
                        std::copysign(BreakawayFrictionNm(m.friction, std::pow(f, m.gearbox.coulomb_exponent), j.qd_rad_s),
                                      j.qd_rad_s);
  return torque * m.drive.ratio * j.qd_rad_s;
}

TEST(GearThermalSimulation, FrictionAtTwoTemperaturesFollowsTheVogelLaw) {
  const RobotConfig robot = FlatPendulum();
  double measured[2] = {0, 0}, predicted[2] = {0, 0};
  const double ambients[2] = {0, 40};
  for (int i = 0; i < 2; ++i) {
    const Recording rec = RunJoint(robot, ambients[i], 4.0);
    for (size_t k = 1; k < rec.t.size(); ++k) {
      const JointTick& j = rec.ticks[k][0];
      EXPECT_NEAR(j.gear_temp_C, ambients[i], 1e-3);
      measured[i] += j.p_friction_W;
      predicted[i] += PredictedFrictionW(robot.modules[0], j);
    }
    RecordProperty("friction_energy_J_at_" + std::to_string(int(ambients[i])) + "C", std::to_string(measured[i] * 0.002));
    EXPECT_NEAR(measured[i], predicted[i], 0.03 * predicted[i]);
  }
  // Cold friction is well above warm: b scales 2.21x from 40 to 0 C, Coulomb 1.49x.
  EXPECT_GT(measured[0] / measured[1], 1.3);
  EXPECT_NEAR(measured[0] / measured[1], predicted[0] / predicted[1], 0.03);
}

TEST(GearThermalSimulation, GearNodeFollowsItsLawFromTheFrictionPower) {
  RobotConfig robot = FlatPendulum();
  GearboxParams& g = robot.modules[0].gearbox;
  g.thermal_resistance_K_per_W = 40;
  g.thermal_time_constant_s = 2.0;
  const double ambient = 25;
  const Recording rec = RunJoint(robot, ambient, 8.0);
  double model_C = ambient, worst = 0, rise = 0;
  for (size_t k = 1; k < rec.t.size(); ++k) {
    const double dt = rec.t[k] - rec.t[k - 1];
    model_C += (ambient + 40 * rec.ticks[k][0].p_friction_W - model_C) * -std::expm1(-dt / 2.0);
    worst = std::max(worst, std::fabs(model_C - rec.ticks[k][0].gear_temp_C));
    rise = std::max(rise, rec.ticks[k][0].gear_temp_C - ambient);
  }
  RecordProperty("gear_rise_K", std::to_string(rise));
  EXPECT_GT(rise, 1.0);
  EXPECT_LT(worst, 0.03 * rise);
}

TEST(GearThermalSimulation, ColdStartFrictionFallsAsTheGearWarmsAndWarmStartBeginsWarm) {
  RobotConfig robot = FlatPendulum();
  GearboxParams& g = robot.modules[0].gearbox;
  g.thermal_resistance_K_per_W = 60;
  g.thermal_time_constant_s = 6.0;
  g.warm_friction_loss_W = 0.5;
  const double period = M_PI;  // sine_pair at 2 rad/s
  nlohmann::json cycle = kSwing;
  cycle["cycle"] = true;
  cycle["cycle_period_s"] = period;
  const Recording cold = RunJoint(robot, 5, 6 * period, cycle);
  // Friction energy per cycle (the same motion each time) falls cycle after cycle.
  std::vector<double> per_cycle(6, 0.0);
  for (size_t k = 1; k < cold.t.size(); ++k) {
    const int c = std::min(5, static_cast<int>(cold.t[k] / period));
    per_cycle[c] += cold.ticks[k][0].p_friction_W * 0.002;
  }
  for (int c = 0; c < 6; ++c) RecordProperty("cycle_" + std::to_string(c) + "_friction_J", std::to_string(per_cycle[c]));
  for (int c = 1; c < 6; ++c) EXPECT_LT(per_cycle[c], per_cycle[c - 1]) << "cycle " << c;
  EXPECT_LT(per_cycle[5], 0.9 * per_cycle[0]);
  EXPECT_GT(cold.ticks.back()[0].gear_temp_C, 5 + 5.0);
  // A warm start begins at the stated duty's steady state: 5 + 60 x 0.5 = 35 C.
  const Recording warm = RunJoint(robot, 5, 0.1, cycle, ThermalStart::kWarm);
  EXPECT_DOUBLE_EQ(warm.ticks[0][0].gear_temp_C, 35);
  EXPECT_EQ(cold.ticks[0][0].gear_temp_C, 5);
}

TEST(GearThermalSimulation, TorqueSensorDriftsWithTheGearTemperature) {
  RobotConfig robot = RobotPreset("pendulum");  // gravity: a steady torque to read
  ModuleParams& m = robot.modules[0];
  m.torque_sensor.noise_Nm = 0;
  m.gearbox.present = true;
  m.gearbox.thermal_time_constant_s = 1e6;
  m.gearbox.sensor_offset_Nm_per_K = 0.05;
  m.gearbox.sensor_gain_per_K = 2e-3;
  const nlohmann::json hold = {{"type", "hold"}, {"angle_deg", 60}};
  double error[2] = {0, 0}, tau[2] = {0, 0};
  const double ambients[2] = {20, 40};
  for (int i = 0; i < 2; ++i) {
    const Recording rec = RunJoint(robot, ambients[i], 2.0, hold);
    const JointTick& j = rec.ticks.back()[0];
    error[i] = j.signals.tau_sensor_Nm - j.tau_true_Nm;
    tau[i] = j.tau_true_Nm;
  }
  const double lsb = m.torque_sensor.full_scale_Nm * 2 / 4095;  // the ADC's step
  EXPECT_NEAR(error[0], 0, lsb);  // calibrated at the reference temperature
  EXPECT_NEAR(error[1] - error[0], 0.05 * 20 + 2e-3 * 20 * tau[1], 2 * lsb);
  EXPECT_GT(std::fabs(tau[1]), 1.0);
}

// A gearbox group whose every effect is zero is today's plant, bit for bit.
TEST(GearThermalSimulation, NeutralGearboxGroupChangesNothing) {
  RobotConfig plain = RobotPreset("pendulum");
  RobotConfig neutral = plain;
  neutral.modules[0].gearbox.present = true;  // vogel_B_K 0, no load friction, no drift, no coupling
  const Recording a = RunJoint(plain, 30, 2.0), b = RunJoint(neutral, 30, 2.0);
  ASSERT_EQ(a.ticks.size(), b.ticks.size());
  for (size_t k = 0; k < a.ticks.size(); ++k) {
    ASSERT_EQ(a.ticks[k][0].q_rad, b.ticks[k][0].q_rad) << k;
    ASSERT_EQ(a.ticks[k][0].p_supply_W, b.ticks[k][0].p_supply_W) << k;
    ASSERT_EQ(a.ticks[k][0].signals.tau_sensor_Nm, b.ticks[k][0].signals.tau_sensor_Nm) << k;
    ASSERT_EQ(a.ticks[k][0].winding_temp_C, b.ticks[k][0].winding_temp_C) << k;
  }
  EXPECT_TRUE(std::isnan(a.ticks.back()[0].gear_temp_C));
}

// Energy balance with the load-dependent friction (previous step's torque) and the rest on:
// supply = stored + losses; electromagnetic work = stored + friction, as without them.
void ExpectBalanceCloses(const RunResult& r, const Recording& rec, double dt, double min_moved_J) {
  ASSERT_TRUE(r.ok) << r.failure_reason;
  double supply = 0, losses = 0, emf = 0, friction = 0, moved = 0;
  for (const JointEnergy& e : r.energy) {
    supply += e.supply_J;
    losses += e.copper_J + e.inverter_J + e.quiescent_J + e.friction_J + e.magnetic_J;
    emf += e.emf_J;
    friction += e.friction_J;
  }
  for (const auto& tick : rec.ticks) {
    for (const JointTick& j : tick) moved += std::fabs(j.p_emf_W) * dt;
  }
  const double stored = (r.kinetic_end_J - r.kinetic_start_J) + (r.potential_end_J - r.potential_start_J);
  EXPECT_GT(moved, min_moved_J);
  EXPECT_NEAR(supply, stored + losses, 0.01 * supply);
  EXPECT_NEAR(emf, stored + friction, 0.01 * moved)
      << "emf " << emf << " J, stored " << stored << " J, friction " << friction << " J, moved " << moved << " J";
}

TEST(LoadFrictionSimulation, EnergyBalanceClosesOnExperiment1WithLoadFriction) {
  RunConfig run = ThesisExperiment1();
  for (ModuleParams& m : run.robot.modules) {
    m.gearbox = Vogel();
    m.gearbox.load_friction_driving = 0.1;
    m.gearbox.load_friction_backdriven = 0.3;
    m.gearbox.thermal_resistance_K_per_W = 20;
    m.gearbox.thermal_time_constant_s = 5;
  }
  const ArmModel model(run.robot);
  Recording rec;
  const RunResult r = Simulate(model, MakeRunSpec(run), rec.Observer());
  ExpectBalanceCloses(r, rec, model.control_dt_s(), 10.0);
  // ... and the load friction really acted: more friction than without it.
  RunConfig plain = ThesisExperiment1();
  Recording rec0;
  const RunResult r0 = Simulate(ArmModel(plain.robot), MakeRunSpec(plain), rec0.Observer());
  RecordProperty("top_joint_friction_J", std::to_string(r.energy[2].friction_J));
  RecordProperty("top_joint_friction_J_without", std::to_string(r0.energy[2].friction_J));
  EXPECT_GT(r.energy[2].friction_J, 1.1 * r0.energy[2].friction_J);
}

TEST(LoadFrictionSimulation, SixJointThermalArmClosesItsEnergyBalanceAndTracks) {
  RunConfig run = RunConfigFromJson(testing_support::UrClassSweepRun(8), "", InputContext{});
  for (ModuleParams& m : run.robot.modules) m.gearbox = ModuleDefaults(m.type + "-thermal", "").gearbox;
  const ArmModel model(run.robot);
  RunSpec spec = MakeRunSpec(run);
  spec.ambient_C = 5;
  Recording rec;
  const RunResult r = Simulate(model, spec, rec.Observer());
  ExpectBalanceCloses(r, rec, model.control_dt_s(), 50.0);
  for (int j = 0; j < 6; ++j) {
    double worst = 0;
    for (const auto& tick : rec.ticks) worst = std::max(worst, std::fabs(tick[j].q_rad - tick[j].signals.q_ref_rad) * 180 / M_PI);
    RecordProperty("worst_tracking_deg_joint_" + std::to_string(j + 1), std::to_string(worst));
    EXPECT_LT(worst, 0.3) << "joint " << j + 1;
  }
}

// ---------------------------------------------------------------- cycles and start modes

TEST(CycleTrajectory, RepeatsItsPeriodAndRejectsACycleThatDoesNotClose) {
  nlohmann::json spec = kSwing;
  spec["cycle"] = true;
  spec["cycle_period_s"] = M_PI;
  const auto cycle = MakeTrajectory(spec, "/joints/1", InputContext{});
  const auto once = MakeTrajectory(kSwing, "/joints/1", InputContext{});
  for (double t : {0.1, 1.0, 2.9}) {
    EXPECT_NEAR(cycle->At(t + 7 * M_PI).q_rad, once->At(t).q_rad, 1e-9);
    EXPECT_NEAR(cycle->At(t + 7 * M_PI).qd_rad_s, once->At(t).qd_rad_s, 1e-9);
  }
  spec["cycle_period_s"] = 2.0;  // not the motion's period: it ends elsewhere
  InputContext ctx;
  ctx.source = "run.json";
  const InputError e = ErrorOf([&] { MakeTrajectory(spec, "/joints/1", ctx); });
  EXPECT_EQ(e.source(), "run.json");
  EXPECT_EQ(e.pointer(), "/joints/1/cycle");
  EXPECT_THAT(e.message(), HasSubstr("does not return to its start after cycle_period_s = 2 s"));
  EXPECT_THAT(e.message(), HasSubstr("mismatch"));
  spec.erase("cycle_period_s");
  EXPECT_EQ(ErrorOf([&] { MakeTrajectory(spec, "/joints/1", ctx); }).pointer(), "/joints/1/cycle_period_s");
  spec["cycle"] = "yes";
  EXPECT_EQ(ErrorOf([&] { MakeTrajectory(spec, "/joints/1", ctx); }).pointer(), "/joints/1/cycle");
  nlohmann::json lone = kSwing;
  lone["cycle_period_s"] = 1;
  EXPECT_EQ(ErrorOf([&] { MakeTrajectory(lone, "/joints/1", ctx); }).pointer(), "/joints/1/cycle_period_s");
}

TEST(StartMode, ColdOrWarmElseAnErrorWithASuggestion) {
  nlohmann::json run = ThesisExperiment1Json();
  run["start"] = "warm";
  EXPECT_EQ(RunConfigFromJson(run, "", InputContext{}).start, ThermalStart::kWarm);
  EXPECT_EQ(MakeRunSpec(RunConfigFromJson(run, "", InputContext{})).start, ThermalStart::kWarm);
  run["start"] = "cold";
  EXPECT_EQ(RunConfigFromJson(run, "", InputContext{}).start, ThermalStart::kCold);
  run["start"] = "Warm";
  InputContext ctx;
  ctx.source = "run.json";
  InputError e = ErrorOf([&] { RunConfigFromJson(run, "", ctx); });
  EXPECT_EQ(e.pointer(), "/start");
  EXPECT_EQ(e.source(), "run.json");
  EXPECT_EQ(e.message(), "unknown start \"Warm\" (known: cold, warm)");
  EXPECT_EQ(e.hint(), "did you mean \"warm\"?");
  run["start"] = 1;
  EXPECT_EQ(ErrorOf([&] { RunConfigFromJson(run, "", ctx); }).pointer(), "/start");
}

}  // namespace
}  // namespace armfault
