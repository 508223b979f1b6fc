// The plant's honest parts: the winding heats with its copper loss through a first-order
// thermal model, and R and K_T follow its temperature; a unit's sensors have gain and offset
// errors the controller does not know; the winding temperature sensor is optional.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "core/monitors/monitor.h"
#include "core/run_config.h"
#include "core/plant/simulation.h"
#include "core/plant/motion/trajectory.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using testing_support::Recording;

// The pendulum held horizontal with a 3 kg tool: a steady current of about 1 A.
RobotConfig HeldPendulum() {
  RobotConfig robot = RobotPreset("pendulum");
  robot.payload_kg = 3.0;
  robot.modules[0].torque_sensor.noise_Nm = 0;
  robot.modules[0].inverter.supply_current_noise_A = 0;
  return robot;
}

Recording Hold(const RobotConfig& robot, double ambient_C, double duration_s,
               const nlohmann::json& motion = {{"type", "hold"}, {"angle_deg", 90}}) {
  const ArmModel model(robot);
  RunSpec spec;
  spec.duration_s = duration_s;
  spec.ambient_C = ambient_C;
  JointRunOptions joint;
  joint.trajectory = MakeTrajectory(motion, "", InputContext{});
  spec.joints = {joint};
  Recording rec;
  EXPECT_TRUE(Simulate(model, spec, rec.Observer()).ok);
  return rec;
}

TEST(WindingTemperature, RisesWithCopperLossAtTheFirstOrderTimeConstant) {
  RobotConfig robot = HeldPendulum();
  robot.modules[0].motor.thermal_resistance_K_per_W = 20;
  robot.modules[0].motor.thermal_time_constant_s = 1.0;
  const double tau = 1.0, rth = 20, ambient = 25;
  // (R and K_T follow the temperature, so the loss grows as it warms: the law is checked
  // against the loss the run really had.)
  const Recording rec = Hold(robot, ambient, 5.0);
  ASSERT_GT(rec.t.size(), 2000u);
  EXPECT_EQ(rec.ticks[0][0].winding_temp_C, ambient);  // starts at ambient

  // The same first-order law integrated from the ticks' mean copper power (2 ms steps).
  double model_C = ambient;
  double worst = 0;
  for (size_t k = 1; k < rec.t.size(); ++k) {
    const double dt = rec.t[k] - rec.t[k - 1];
    model_C += (ambient + rth * rec.ticks[k][0].p_copper_W - model_C) * -std::expm1(-dt / tau);
    worst = std::max(worst, std::fabs(model_C - rec.ticks[k][0].winding_temp_C));
  }
  const double p_end = rec.ticks.back()[0].p_copper_W;
  const double rise_end = rec.ticks.back()[0].winding_temp_C - ambient;
  RecordProperty("copper_W", std::to_string(p_end));
  RecordProperty("rise_K", std::to_string(rise_end));
  EXPECT_GT(p_end, 0.8);                   // about 1 A through two phases of 0.6 ohm
  EXPECT_LT(worst, 0.02 * rise_end);       // the simulation follows the law
  EXPECT_NEAR(rise_end, rth * p_end, 0.03 * rise_end);  // 5 time constants: settled
}

TEST(WindingTemperature, AWarmAmbientRaisesResistanceAndCopperLoss) {
  RobotConfig robot = HeldPendulum();
  robot.modules[0].motor.thermal_resistance_K_per_W = 0;  // no self-heating: T = ambient
  // Moving (friction is then kinetic, so the torque the motion needs is fixed).
  const nlohmann::json swing = {{"type", "sine_pair"}, {"amplitude_deg", 25}, {"omega_rad_s", 1.2732}, {"offset_deg", 60}};
  const Recording cold = Hold(robot, 20, 4.0, swing);
  const Recording warm = Hold(robot, 45, 4.0, swing);
  const double r20 = robot.modules[0].motor.phase_resistance_ohm;
  const double r_factor = 1 + 0.00393 * 25, kt_factor = 1 - 0.001 * 25;
  double p_cold = 0, p_warm = 0;
  for (size_t k = 500; k < warm.t.size(); ++k) {
    const JointTick& w = warm.ticks[k][0];
    // Copper loss over sum of squared phase currents is the winding's resistance at 45 C.
    ASSERT_NEAR(w.p_copper_W / w.current_sq_A2, r20 * r_factor, 1e-9 * r20);
    EXPECT_EQ(w.winding_temp_C, 45.0);
    p_cold += cold.ticks[k][0].p_copper_W;
    p_warm += w.p_copper_W;
  }
  // Holding the same load: K_T is 2.5 % lower, so the current is 1/0.975 times higher, and R
  // is 9.8 % higher: the copper loss rises by 1.098 / 0.975^2 = 1.155.
  RecordProperty("copper_ratio", std::to_string(p_warm / p_cold));
  EXPECT_NEAR(p_warm / p_cold, r_factor / (kt_factor * kt_factor), 0.01);
}

TEST(WindingTemperature, ThesisExperiment1WarmsTheTopWindingByItsCopperEnergyOverItsHeatCapacity) {
  // 10 s is short against the 900 s time constant: the rise is E_copper / C, C = tau / R_th.
  const RunConfig run = ThesisExperiment1();
  const ArmModel model(run.robot);
  Recording rec;
  const RunResult result = Simulate(model, MakeRunSpec(run), rec.Observer());
  ASSERT_TRUE(result.ok);
  const MotorParams& m = run.robot.modules[2].motor;
  const double rise = rec.ticks.back()[2].winding_temp_C - 20.0;
  const double heat_capacity_J_per_K = m.thermal_time_constant_s / m.thermal_resistance_K_per_W;
  RecordProperty("exp1_top_rise_K", std::to_string(rise));
  RecordProperty("exp1_top_copper_J", std::to_string(result.energy[2].copper_J));
  EXPECT_GT(rise, 0.0);
  EXPECT_NEAR(rise, result.energy[2].copper_J / heat_capacity_J_per_K, 0.02 * rise);
}

TEST(WindingTemperature, TheSensorIsReadOnlyWhereTheModuleHasOne) {
  RobotConfig robot = HeldPendulum();
  const Recording without = Hold(robot, 30, 0.1);
  EXPECT_TRUE(std::isnan(without.ticks.back()[0].signals.winding_temp_C));
  robot.modules[0].winding_temperature_sensor = true;
  const Recording with = Hold(robot, 30, 0.1);
  EXPECT_EQ(with.ticks.back()[0].signals.winding_temp_C, with.ticks.back()[0].winding_temp_C);
  EXPECT_GE(with.ticks.back()[0].signals.winding_temp_C, 30.0);
}

TEST(SensorErrors, GainAndOffsetActOnTheTrueValueTheControllerMapsNominally) {
  RobotConfig robot = HeldPendulum();
  robot.modules[0].torque_sensor.gain_error = 0.03;
  robot.modules[0].torque_sensor.offset_error_Nm = 0.5;
  robot.modules[0].inverter.supply_current_gain_error = -0.02;
  robot.modules[0].inverter.supply_current_offset_error_A = 0.1;
  const Recording rec = Hold(robot, 20, 1.0);
  const JointTick& t = rec.ticks.back()[0];
  // The reading is the erroneous value within one ADC step (28 N m / 2047.5).
  EXPECT_NEAR(t.signals.tau_sensor_Nm, 1.03 * t.tau_true_Nm + 0.5, 28.0 / 2047.5);
  EXPECT_GT(std::fabs(t.tau_true_Nm), 10.0);
  EXPECT_NEAR(t.signals.i_supply_meas_A, 0.98 * t.i_supply_A + 0.1, 1e-12);
}

}  // namespace
}  // namespace armfault
