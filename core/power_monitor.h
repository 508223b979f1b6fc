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
// Thresholds (health states, debounce, significance) are data: MonitorConfig.
#pragma once

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <vector>

#include "core/detector_statistics.h"
#include "core/json_input.h"
#include "core/monitor.h"
#include "core/robot_config.h"

namespace armfault {

// Worn / defective limits of one estimated parameter. For a factor whose healthy value is
// 1, "below" limits apply to falling parameters (K_T), "above" to rising ones (friction).
struct StateLimits {
  double worn = 0;
  double defective = 0;
};

struct MonitorConfig {
  // windows
  double rest_velocity_rad_s = 0.02;   // |qd| below this: at rest (eq 4-11), no window
  double min_window_s = 0.3;           // shorter windows are not judged
  double min_window_energy_J = 0.5;    // |E_out| and |E_mesh_in| below this: not judged
  int mechanical_windows = 3;          // windows in the mechanical fit
  // electrical fit
  double electrical_time_constant_s = 1.5;  // forgetting of the per-tick fit
  double min_rotor_energy_J = 2.0;     // weighted sum of |P_rotor| dt needed to judge n
  double min_copper_energy_J = 0.2;    // weighted sum of P_copper dt needed to judge rho
  // decision
  double significance = 3.0;           // (|deviation| - worn margin) / std error must exceed this
  double debounce_s = 0.3;             // a candidate verdict must hold this long to alarm
  StateLimits kt_factor{0.93, 0.75};          // below
  StateLimits friction_factor{1.30, 1.80};    // above
  StateLimits resistance_factor{1.40, 2.00};  // above
  StateLimits sensor_drift_Nm{1.0, 3.0};      // |d| above
  // tick-level detectors
  double overpower_W = 40.0;           // supply power above the electrical model by this: short
  double overpower_time_s = 0.002;
  double dead_drive_current_A = 2.0;   // |i_cmd| at least this with no copper loss drawn ...
  double dead_drive_time_s = 0.02;     // ... this long: the bridge is open (tripped)
  double stuck_time_s = 0.2;           // reading unchanged this long ...
  double stuck_torque_span_Nm = 3.0;   // ... while the commanded torque moved this much
  double rail_time_s = 0.05;           // reading at an ADC rail this long
  double blocked_current_A = 3.0;      // |i_cmd| at least this ...
  double blocked_error_rad = 0.02;     // ... tracking error at least this ...
  double blocked_time_s = 0.2;         // ... with the joint at rest, this long
};

// The worn/defective limits a swept detector uses.
StateLimits MonitorConfig::*LimitsOf(Detector detector);

// Parses a monitor JSON object (every key optional, unknown keys rejected); Validate()s it.
MonitorConfig MonitorConfigFromJson(const nlohmann::json& value, const std::string& pointer,
                                    const std::string& source);
nlohmann::json MonitorConfigToJson(const MonitorConfig& config);
void Validate(const MonitorConfig& config, const std::string& pointer, const std::string& source);

// What the monitor knows about one joint module: its datasheet (nominal) parameters, taken
// from the robot config. The monitor never sees the hardware condition of a run.
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
  double rotor_coupling_kg_m2 = 0;     // I_m ratio: rotor coupling to lower joints (eq 3-7, 4-14)
  std::vector<double> coupling;        // per lower joint: a_i . a_j at the zero pose
  double sensor_min_Nm = 0, sensor_max_Nm = 0;  // readings at the ADC rails
};

// Immutable, shared by all runs of a robot.
struct PowerMonitorModel {
  MonitorConfig config;
  std::vector<JointKnowledge> joints;
  double control_dt_s = 0;
  DetectorThresholds thresholds{};  // from the config's worn limits
  long hold_span = 1;               // ticks a statistic must hold: debounce_s / control_dt_s + 1
};
PowerMonitorModel MakePowerMonitorModel(const RobotConfig& robot, const MonitorConfig& config);

class PowerEfficiencyMonitor : public HealthMonitor {
 public:
  explicit PowerEfficiencyMonitor(const PowerMonitorModel& model);
  ~PowerEfficiencyMonitor() override;
  void Observe(double t_s, const std::vector<JointSignals>& joints) override;
  void Finish(double t_end_s) override;
  const MonitorOutput& output() const override { return output_; }

  // Latest estimates of a joint (0-based), for tests and traces.
  struct Estimates {
    double kt_factor = 1, kt_factor_se = 0;
    double resistance_factor = 1, resistance_factor_se = 0;
    double friction_factor = 1, friction_factor_se = 0;
    double sensor_drift_Nm = 0, sensor_drift_se = 0;
    int windows_in_fit = 0;
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
  std::vector<JointSignals> previous_;
  double t_prev_ = 0;
  long ticks_ = 0;
  MonitorOutput output_;
};

}  // namespace armfault
