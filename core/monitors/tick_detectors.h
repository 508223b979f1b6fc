// What one joint's estimators take from one controller tick, and the tick-level detectors that
// latch on events rather than judge a fitted parameter (docs/monitor.md, "Tick detectors").
//
// Inputs: this tick's and the previous tick's JointSignals, the joint's knowledge (calibration,
// sensor rails, brake), the window direction (0 at rest).
// Outputs: TickTerms (the motion and the powers over the control period just ended) and, per
// tick, the Candidate of the first tick-level detector that fires (healthy when none does):
//  - inverter short: U_d I_d - (max(0, P_r) + P_copper + P_fixed) > overpower_W for overpower_time_s;
//  - dead drive: |i| >= dead_drive_current_A with less than dead_drive_draw_fraction of the
//    expected draw, for dead_drive_time_s (the bridge tripped);
//  - stuck torque sensor: on an ADC rail for rail_time_s (not reached gradually: saturation), or
//    unchanged for stuck_time_s while the commanded torque swings stuck_torque_span_Nm;
//  - locked joint: at rest, |i| >= blocked_current_A, tracking error >= blocked_error_rad for
//    blocked_time_s: the brake if the sensor reads under brake_torque_fraction of the motor torque.
#pragma once

#include <limits>
#include <string>

#include "core/monitors/power_monitor.h"

namespace armfault {

struct TickTerms {
  double dq = 0;            // encoder travel over the period [rad]
  double i = 0;             // the command held over the period [A]
  double tau_mean = 0;      // mean torque-sensor reading over the period [N m]
  double rotor_torque = 0;  // rotor torque the command gives, as perceived at the link [N m]
  double p_supply = 0;      // U_d I_d [W]
  double p_rotor = 0, p_copper = 0, p_fixed = 0;  // the calibration's terms of the supply power [W]
  double winding_above_K = std::numeric_limits<double>::quiet_NaN();  // a declared winding sensor's reading over the calibration's [K]
};
// A declared winding-temperature sensor lets the monitor follow copper resistance and magnet
// strength from the temperature its calibration holds at (magnet_kt_loss_per_K, copper_resistance_per_K).
TickTerms TermsOf(const MonitorConfig& c, const JointKnowledge& k, const JointSignals& now, const JointSignals& prev,
                  double dt_s);

// A candidate verdict before debounce.
struct Candidate {
  HealthState state = HealthState::kHealthy;
  std::string family;
  std::string magnitude_name;
  double magnitude = 0;
  double confidence = 0;
  bool structural = false;  // from a tick-level detector: latched once committed
};

// The tick-level detectors' timers of one joint.
struct TickDetectors {
  // The timers after this tick, and the candidate of the first detector that fires.
  Candidate Update(const MonitorConfig& c, const JointKnowledge& k, const TickTerms& x, const JointSignals& now,
                   const JointSignals& prev, int dir, double dt_s);
  double overpower_s = 0;
  double dead_s = 0;
  double flat_s = 0, flat_dq = 0, flat_cmd_min = 0, flat_cmd_max = 0, flat_ref_min = 0, flat_ref_max = 0;
  double rail_s = 0;
  bool rail_saturated = false;  // the reading reached its rail gradually: saturation, no evidence
  double blocked_s = 0;
};

}  // namespace armfault
