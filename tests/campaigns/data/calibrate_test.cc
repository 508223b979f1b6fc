// Calibrating a twin (campaigns/data/calibrate.h): units with drawn parameters and sensor noise are
// simulated on a healthy motion; calibration from their signals alone must bracket what each
// unit drew, in at least 90 % of the units, for every parameter it calls identifiable.
#include "campaigns/data/calibrate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>

#include "core/base/json_input.h"
#include "core/base/rng.h"
#include "core/plant/simulation.h"
#include "core/run_config.h"

namespace armfault {
namespace {

struct Drawn {
  RobotConfig robot;
  double payload_kg = 0;
  std::vector<std::map<std::string, double>> truth;  // per joint, by parameter key
};

// A unit of mrr-config1 with every calibrated parameter drawn around the datasheet.
Drawn DrawUnit(uint64_t seed) {
  Drawn d;
  d.robot = RobotPreset("mrr-config1");
  Rng rng(seed);
  auto spread = [&](double half) { return 1.0 + half * (2.0 * rng.Uniform() - 1.0); };
  d.robot.payload_kg = d.payload_kg = 2.0 * rng.Uniform();
  for (ModuleParams& m : d.robot.modules) {
    m.motor.kt_Nm_per_A *= spread(0.08);
    m.motor.phase_resistance_ohm *= spread(0.15);
    m.motor.rotor_inertia_kg_m2 *= spread(0.05);
    m.inverter.quiescent_power_W *= spread(0.3);
    m.drive.mesh_loss_fraction *= spread(0.3);
    m.friction.viscous_Nm_s_per_rad *= spread(0.3);
    m.friction.coulomb_Nm *= spread(0.3);
    m.friction.static_Nm *= spread(0.3);
    m.torque_sensor.gain_error = 0.03 * (2.0 * rng.Uniform() - 1.0);
    m.torque_sensor.offset_error_Nm = 0.3 * (2.0 * rng.Uniform() - 1.0);
    d.truth.push_back({{"motor/kt_Nm_per_A", m.motor.kt_Nm_per_A},
                       {"motor/phase_resistance_ohm", m.motor.phase_resistance_ohm},
                       {"motor/rotor_inertia_kg_m2", m.motor.rotor_inertia_kg_m2},
                       {"inverter/quiescent_power_W", m.inverter.quiescent_power_W},
                       {"drive/mesh_loss_fraction", m.drive.mesh_loss_fraction},
                       {"friction/viscous_Nm_s_per_rad", m.friction.viscous_Nm_s_per_rad},
                       {"friction/coulomb_Nm", m.friction.coulomb_Nm},
                       {"friction/static_Nm", m.friction.static_Nm},
                       {"torque_sensor/gain_error", m.torque_sensor.gain_error},
                       {"torque_sensor/offset_error_Nm", m.torque_sensor.offset_error_Nm}});
  }
  return d;
}

// The healthy log of `robot` on a motion of every joint, both ways, at several speeds.
std::vector<std::vector<JointSignals>> HealthyLog(const RobotConfig& robot, double duration_s, uint64_t seed,
                                                  double* control_dt_s) {
  nlohmann::json run = {{"robot", "mrr-config1"},
                        {"duration_s", duration_s},
                        {"seed", seed},
                        {"joints",
                         {{"1", {{"type", "sine_pair"}, {"amplitude_deg", 40}, {"omega_rad_s", 1.1}}},
                          {"2", {{"type", "sine_pair"}, {"amplitude_deg", 35}, {"omega_rad_s", 1.3}}},
                          {"3", {{"type", "sine_pair"}, {"amplitude_deg", 40}, {"omega_rad_s", 1.7}}}}}};
  RunConfig config = RunConfigFromJson(run, "", InputContext{});
  config.robot = robot;
  const ArmModel model(config.robot);
  *control_dt_s = model.control_dt_s();
  std::vector<std::vector<JointSignals>> log;
  const RunResult r = Simulate(model, MakeRunSpec(config), [&](const Tick& tick) {
    std::vector<JointSignals> row;
    for (const JointTick& j : *tick.joints) row.push_back(j.signals);
    log.push_back(std::move(row));
  });
  EXPECT_TRUE(r.ok) << r.failure_reason;
  return log;
}

TEST(Calibrate, IntervalsCoverTheDrawnUnitsAndTheTwinTakesThem) {
  constexpr int kUnits = 20;
  std::map<std::string, int> covered, identified;
  int payload_covered = 0, payload_identified = 0;
  int first_unit_printed = 0;
  for (int u = 0; u < kUnits; ++u) {
    const Drawn unit = DrawUnit(1000 + u);
    double dt = 0;
    const auto log = HealthyLog(unit.robot, 40, 77 + u, &dt);
    const UnitCalibration cal = CalibrateUnit(RobotPreset("mrr-config1"), dt, log, CalibrationOptions{});
    ASSERT_EQ(cal.joints.size(), 3u);
    if (cal.payload.identifiable) {
      ++payload_identified;
      if (unit.payload_kg >= cal.payload.low && unit.payload_kg <= cal.payload.high) ++payload_covered;
      EXPECT_EQ(cal.twin.payload_kg, cal.payload.estimate);
    }
    if (u == first_unit_printed) {
      std::printf("payload truth %.6g estimate %.6g [%.6g, %.6g]\n", unit.payload_kg, cal.payload.estimate, cal.payload.low,
                  cal.payload.high);
    }
    for (const JointCalibration& jc : cal.joints) {
      for (const CalibratedParameter& p : jc.parameters) {
        const double truth = unit.truth[jc.joint - 1].at(p.key);
        const std::string key = "j" + std::to_string(jc.joint) + " " + p.key;
        if (!p.identifiable) continue;
        ++identified[key];
        if (truth >= p.low && truth <= p.high) ++covered[key];
        if (u == first_unit_printed) {
          std::printf("%-36s truth %.6g estimate %.6g [%.6g, %.6g]\n", key.c_str(), truth, p.estimate, p.low, p.high);
        }
      }
      // The twin holds what was identified.
      if (const CalibratedParameter* kt = FindParameter(jc, "motor/kt_Nm_per_A"); kt && kt->identifiable) {
        EXPECT_EQ(cal.twin.modules[jc.joint - 1].motor.kt_Nm_per_A, kt->estimate);
      }
    }
  }
  for (const auto& [key, n] : identified) {
    const int c = covered.count(key) ? covered.at(key) : 0;
    std::printf("coverage %-36s %d/%d\n", key.c_str(), c, n);
    EXPECT_GE(c, 0.9 * n) << key;
  }
  std::printf("coverage payload_kg %d/%d\n", payload_covered, payload_identified);
  EXPECT_GE(payload_identified, kUnits * 9 / 10);
  EXPECT_GE(payload_covered, 0.9 * payload_identified);
  // The parameters the motion excites must be identified on most units.
  for (const char* key : {"motor/kt_Nm_per_A", "friction/coulomb_Nm", "torque_sensor/offset_error_Nm",
                          "inverter/quiescent_power_W"}) {
    for (int j = 1; j <= 3; ++j) {
      const std::string k = "j" + std::to_string(j) + " " + key;
      EXPECT_GE(identified[k], kUnits / 2) << k;
    }
  }
  for (int j = 2; j <= 3; ++j) {
    EXPECT_GE(identified["j" + std::to_string(j) + " torque_sensor/gain_error"], kUnits / 2);
    EXPECT_GE(identified["j" + std::to_string(j) + " drive/mesh_loss_fraction"], kUnits / 2);
  }
  // Joint 1 turns about the vertical and carries only inertia: its sensor's gain cannot be told
  // from the rotor's inertia (both scale with the acceleration), and calibration says so.
  EXPECT_LE(identified["j1 torque_sensor/gain_error"], 2);
}

TEST(Calibrate, TooShortALogIsAnError) {
  double dt = 0;
  const auto log = HealthyLog(RobotPreset("mrr-config1"), 2, 1, &dt);
  try {
    CalibrateUnit(RobotPreset("mrr-config1"), dt, log, CalibrationOptions{});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("at least two bootstrap blocks"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace armfault
