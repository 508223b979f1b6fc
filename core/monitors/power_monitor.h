// The power-efficiency health monitor (thesis chapter 4, extended to isolate and size faults).
//
// Inputs per controller tick and joint: JointSignals only (reference, encoder, velocity
// estimate, torque sensor, commanded current, supply current, bus voltage).
// Outputs: MonitorOutput (verdicts and per-window efficiencies).
//
// Per joint it keeps three estimators (all definitions in docs/monitor.md):
//  - electrical balance, every tick, weighted least squares with forgetting:
//      U_d I_d - P_inverter - P_quiescent = n P_rotor + rho P_copper
//    with P_rotor = ratio K_T i_cmd dq/dt and P_copper = 2 R i_cmd^2: n estimates the K_T
//    factor, rho the winding-resistance factor;
//  - mechanical balance over windows bounded by zero velocity (inertia drops out, eq 4-18):
//      n E_rotor - E_out - mesh_loss = k E_friction - d dq
//    k estimates the friction factor, d a torque-sensor drift [N m];
//  - tick-level detectors: supply over-power (inverter short), a torque reading that does
//    not follow the commanded torque or sits on a rail (stuck sensor), commanded motion with
//    a still encoder, high current and a torque that never reaches the sensor (brake).
// Thresholds (health states, debounce, significance) and every tuned constant of the estimators
// are data: MonitorConfig (core/monitors/monitor_config.h). The estimators' parts, each with its
// inputs, outputs and equations: electrical_fit.h (the electrical balance and the winding as a
// thermometer), torque_balance.h, friction_reference.h (the friction the run finds),
// tick_detectors.h.
#pragma once

#include <nlohmann/json.hpp>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "core/base/json_input.h"
#include "core/monitors/detector_statistics.h"
#include "core/monitors/friction_model.h"
#include "core/monitors/friction_reference.h"
#include "core/monitors/monitor.h"
#include "core/monitors/monitor_config.h"
#include "core/monitors/torque_balance.h"
#include "core/monitors/virtual_torque_sensor.h"
#include "core/plant/robot/robot_config.h"

namespace armfault {

// The worn/defective limits a swept detector uses.
StateLimits MonitorConfig::*LimitsOf(Detector detector);

// The electrical balance the monitor believes of one unit (thesis eq 4-4 ... 4-8):
//   U_d I_d = quiescent + rotor_gain P_r + (copper + conduction) i² + switching |i|
// with P_r = γ K_T i q̇ from the datasheet K_T. From the datasheet, or fitted by commissioning.
struct ElectricalCalibration {
  double quiescent_W = 0;
  double rotor_gain = 1.0;             // supply power per perceived rotor power
  double copper_W_per_A2 = 0;          // 2 R: scales with the winding resistance
  double conduction_W_per_A2 = 0;      // 2 R_sw: the switches' conduction loss
  double switching_W_per_A = 0;        // 2 U_d t_sw f_pwm
  double reference_temp_C = 20.0;      // winding temperature the values hold at (datasheet: 20 °C)
  double Copper(double i) const { return copper_W_per_A2 * i * i; }
  double Fixed(double i) const { return quiescent_W + conduction_W_per_A2 * i * i + switching_W_per_A * std::fabs(i); }
};

// What the monitor knows about one joint module: its datasheet (nominal) parameters, taken
// from the robot config, and what commissioning on the unit taught it. The monitor never
// sees the hardware condition of a run.
struct JointKnowledge {
  double ratio = 0;
  double kt_Nm_per_A = 0;
  double phase_resistance_ohm = 0;
  double switch_resistance_ohm = 0;
  double switching_loss_W_per_A = 0;   // U_d t_sw f_pwm per conducting leg
  double quiescent_W = 0;
  double mesh_loss_fraction = 0;
  FrictionParams friction;             // nominal
  double brake_holding_Nm = 0;         // motor side
  double rotor_inertia_link_kg_m2 = 0; // I_m ratio^2: the rotor reflected to the link
  std::vector<double> coupling;        // per lower joint: a_i . a_j at the zero pose
  double sensor_min_Nm = 0, sensor_max_Nm = 0;  // readings at the ADC rails
  // No torque sensor: its reading is the model's (virtual_torque_sensor.h), so the stuck and
  // drift detectors are off on this joint.
  bool torque_sensor = true;
  // The unit as the monitor believes it: the datasheet's values until commissioning fits them.
  bool commissioned = false;
  ElectricalCalibration electrical;
  MechanicalCalibration mechanical;
  double balance_sigma_Nm = 0.05;      // healthy scatter of one tick's balance residual
  // How far the supply power's constant part may lie from the calibration's [W] (1 sigma):
  // the datasheet's spread of quiescent draw and current-sensor offset, or what is left of it
  // after commissioning (warm-up of the electronics).
  double constant_power_sd_W = 0.1;
};

// Immutable, shared by all runs of a robot.
struct PowerMonitorModel {
  MonitorConfig config;
  std::vector<JointKnowledge> joints;
  double control_dt_s = 0;
  DetectorThresholds thresholds{};  // from the config's worn limits (where the magnitude fit starts)
  // What the held statistics alarm against (detector_statistics.h, Alarms): "threshold", the
  // worn limits' thresholds and the significance; "sequential", each CUSUM's h
  // (sequential_test.h) and kSequentialSignificance, over `sequential_tests` CUSUMs.
  bool sequential = false;
  DetectorThresholds decision_thresholds{};
  double decision_significance = 0;
  int sequential_tests = 0;
  long hold_span = 1;               // ticks a statistic must hold: debounce_s / control_dt_s + 1 (1: sequential)
  VirtualTorqueSensor virtual_sensor;  // the readings of the joints without a torque sensor
};
PowerMonitorModel MakePowerMonitorModel(const RobotConfig& robot, const MonitorConfig& config);

// The monitor model of one unit after commissioning: PowerMonitorCommissioning
// (core/monitors/commissioning.h), streamed tick by tick.

class PowerEfficiencyMonitor : public HealthMonitor {
 public:
  explicit PowerEfficiencyMonitor(const PowerMonitorModel& model);
  ~PowerEfficiencyMonitor() override;
  void Observe(double t_s, const std::vector<JointSignals>& joints) override;
  void Finish(double t_end_s) override;
  const MonitorOutput& output() const override { return output_; }
  void KeepWindows(bool keep) override { keep_windows_ = keep; }
  // Updates the joints' estimators last joint first within each tick (for the test that the
  // order changes nothing); the outputs are the same either way.
  void UpdateJointsInReverseOrder(bool reverse) { reverse_joint_order_ = reverse; }
  // Its swept detectors' held statistics (DecisionStats, core/monitors/detector_statistics.h).
  std::unique_ptr<DecisionTap> NewDecisionTap(double onset_s) const override;

  // Latest estimates of a joint (0-based), for tests and traces.
  struct Estimates {
    double kt_factor = 1, kt_factor_se = 0;
    double resistance_factor = 1, resistance_factor_se = 0;
    double friction_factor = 1, friction_factor_se = 0;  // over friction_reference
    // The joint's whole friction (curve, mesh and load friction) against the healthy one at the
    // same motion: what a wear of friction_increase's factor k makes k (docs/monitor.md).
    double friction_torque_factor = 1;
    double friction_reference = 1;  // the friction the run found, against the calibration (docs/monitor.md)
    double sensor_drift_Nm = 0, sensor_drift_se = 0;
    int windows_in_fit = 0;      // windows in the (thesis-view) mechanical window fit
    double window_friction_factor = 1;  // the window fit's friction factor
    double torque_gain = 1, torque_gain_se = 0;  // the torque balance's a
    double balance_moving_s = 0;  // moving time in the balance fit
  };
  Estimates estimates(int joint) const;
  // The swept detectors' held statistics at the latest tick (see detector_statistics.h), and
  // the family of a latched tick-level alarm ("" if none), of a joint (0-based).
  const DetectorReadings& readings(int joint) const;
  const std::string& structural_family(int joint) const;
  int joint_count() const { return static_cast<int>(joints_.size()); }

  struct JointState;  // per-joint run data (defined in the .cc)

 private:
  const PowerMonitorModel& model_;
  std::vector<std::unique_ptr<JointState>> joints_;
  std::vector<ArmJoint> arm_joints_;  // the joints as the arm's readings see them
  ArmFrictionModel friction_model_;   // "friction_reference": "arm_model"
  std::vector<double> winding_above_K_;  // this tick's declared winding readings, for it
  double t_first_ = 0;
  std::vector<JointSignals> previous_;
  std::vector<JointSignals> filled_;  // this tick's signals with the virtual torque readings
  double t_prev_ = 0;
  long ticks_ = 0;
  bool keep_windows_ = true;
  bool reverse_joint_order_ = false;
  MonitorOutput output_;
};

}  // namespace armfault
