// The ur-class arm without torque sensors: the readings are NaN, the controller tracks on the
// model's feedforward and the energy balance still closes; the monitor's virtual sensor
// (core/monitors/virtual_torque_sensor.h), from the signals alone, against the true
// transmitted torque (the cross-check the issue asks of a monitor's estimate).
#include "core/monitors/virtual_torque_sensor.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/plant/simulation.h"
#include "core/run_config.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

TEST(VirtualTorqueSensorTest, SensorlessArmTracksAndTheModelReadsItsTorques) {
  const nlohmann::json run_json = testing_support::UrClassSweepRun(8);
  RunConfig run = RunConfigFromJson(run_json, "", InputContext{});
  for (ModuleParams& m : run.robot.modules) m.torque_sensor.present = false;
  run.robot.payload_kg = 1.0;
  const ArmModel model(run.robot);
  testing_support::Recording rec;
  const RunResult r = Simulate(model, MakeRunSpec(run), rec.Observer());
  ASSERT_TRUE(r.ok) << r.failure_reason;

  double supply = 0, losses = 0;
  for (const JointEnergy& e : r.energy) {
    supply += e.supply_J;
    losses += e.copper_J + e.inverter_J + e.quiescent_J + e.friction_J + e.magnetic_J;
  }
  const double stored = (r.kinetic_end_J - r.kinetic_start_J) + (r.potential_end_J - r.potential_start_J);
  EXPECT_NEAR(supply, stored + losses, 0.01 * supply);

  // Tick by tick the virtual reading carries the noise of a differenced velocity estimate; the
  // monitor low-passes it (its balance filter, its windows). So compared here: means over 50 ms.
  // Measured: 0.4 % (joints 2-5) to 1.8 % (joint 1) of each joint's rms torque.
  const VirtualTorqueSensor sensor = MakeVirtualTorqueSensor(run.robot);
  ASSERT_TRUE(sensor.any());
  constexpr int kBlock = 25;
  std::vector<double> worst_deg(6, 0.0), err2(6, 0.0), ref2(6, 0.0), sum_model(6, 0.0), sum_true(6, 0.0);
  std::vector<JointSignals> prev, now;
  long blocks = 0;
  for (size_t k = 0; k < rec.ticks.size(); ++k) {
    now.clear();
    for (int j = 0; j < 6; ++j) {
      const JointTick& tick = rec.ticks[k][j];
      EXPECT_TRUE(std::isnan(tick.signals.tau_sensor_Nm)) << "tick " << k << " joint " << j + 1;
      worst_deg[j] = std::max(worst_deg[j], std::fabs(tick.q_rad - tick.signals.q_ref_rad) * 180 / M_PI);
      now.push_back(tick.signals);
    }
    if (k > 0) {
      sensor.Fill(prev, model.control_dt_s(), &now);
      for (int j = 0; j < 6; ++j) {
        sum_model[j] += now[j].tau_sensor_Nm;
        sum_true[j] += rec.ticks[k][j].tau_true_Nm;
      }
      if (k % kBlock == 0) {
        ++blocks;
        for (int j = 0; j < 6; ++j) {
          err2[j] += std::pow((sum_model[j] - sum_true[j]) / kBlock, 2);
          ref2[j] += std::pow(sum_true[j] / kBlock, 2);
          sum_model[j] = sum_true[j] = 0;
        }
      }
    }
    prev = now;
  }
  for (int j = 0; j < 6; ++j) {
    const double error_Nm = std::sqrt(err2[j] / blocks), torque_Nm = std::sqrt(ref2[j] / blocks);
    RecordProperty("worst_tracking_deg_joint_" + std::to_string(j + 1), std::to_string(worst_deg[j]));
    RecordProperty("virtual_torque_rms_error_Nm_joint_" + std::to_string(j + 1), std::to_string(error_Nm));
    RecordProperty("true_torque_rms_Nm_joint_" + std::to_string(j + 1), std::to_string(torque_Nm));
    EXPECT_LT(worst_deg[j], 0.5) << "joint " << j + 1;
    EXPECT_LT(error_Nm, 0.05 * torque_Nm) << "joint " << j + 1;
  }
}

}  // namespace
}  // namespace armfault
