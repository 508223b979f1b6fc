// A twin of one unit: its drive parameters fitted to a recorded healthy log by least squares
// on the model's own equations (`armfault calibrate`, docs/calibration.md).
//
// Inputs: the nominal robot (the datasheet: preset, robot file or URDF), the log's controller
// ticks (JointSignals of every joint, time order, the robot's control period), options.
// Outputs: per joint, each parameter's estimate with a 95 % interval from a block bootstrap
// over the log (so that residuals coloured by the controller and quantisation widen it),
// flagged not identifiable where the motion does not pin it down; the residuals' RMS; and the
// twin: the nominal robot with every identifiable value replaced.
//
// Equations, per joint (thesis eq 3-7 and 4-4 ... 4-8; the monitor's two balances,
// core/monitors/torque_balance.h and power_monitor.h), with P = γ K_T° i the torque the
// datasheet K_T° makes of the commanded current i (held over the control period):
//   electrical, per period:  U_d I_d = P_0 + k P q̇ + 2(R + R_sw) i² + c |i|
//   mechanical, filtered:    τ_s = s k P − s I_r q̈ − μ |τ_s| sgn q̇ − s γ f(q̇) + d
// with k = K_T / K_T°, f the motor-side friction curve (b, F_c, F_s; F_t the datasheet's), s
// the torque sensor's gain (1 + gain_error) and d its offset. The electrical fit gives k; the
// mechanical one s k, hence s, and the rest divided by s.
//
// What one log cannot separate (docs/calibration.md): K_T from the supply-current sensor's
// gain (the electrical balance sees (1 + g_I) K_T), the winding from the switches'
// resistance (R_sw stays the datasheet's), the quiescent draw from the supply sensor's offset
// × U_d. Without a winding-temperature sensor the values hold at the log's temperature.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/plant/robot/robot_config.h"
#include "core/signals/joint_signals.h"

namespace armfault {

struct CalibrationOptions {
  double block_s = 2.0;       // bootstrap block: longer than the controller's and filter's memory
  int resamples = 400;        // bootstrap resamples
  uint64_t seed = 1;          // the bootstrap's draws: the same log gives the same intervals
  // Not identifiable: the interval's half-width beyond this fraction of the datasheet value.
  double identifiable_spread = 0.5;
  // Rounds of the bias correction: the twin runs the log's reference and is fitted again.
  int bias_iterations = 4;
};

struct CalibratedParameter {
  std::string key;   // in the module's JSON: "motor/kt_Nm_per_A"
  std::string unit;
  double nominal = 0, estimate = 0, low = 0, high = 0;  // low, high: the 95 % interval
  bool identifiable = true;
};

struct JointCalibration {
  int joint = 0;                 // 1-based
  long electrical_rows = 0;      // periods in the electrical fit
  long balance_rows = 0;         // filtered ticks in the torque balance (moving one way)
  std::vector<CalibratedParameter> parameters;
  double power_rms_W = 0;        // electrical balance's residual
  double current_rms_A = 0;      // the same as supply current (over the mean bus voltage)
  double torque_rms_Nm = 0;      // torque balance's residual (filtered)
  double winding_temp_C = 0;     // mean of the winding sensor; NaN without one
};

struct UnitCalibration {
  std::vector<JointCalibration> joints;
  // The payload at the tool [kg], from the torques of every joint with a sensor (rigid-body
  // model along the log's reference); not identifiable if the motion hardly loads it.
  CalibratedParameter payload;
  int blocks = 0;                // bootstrap blocks in the log
  RobotConfig twin;
};

// Throws InputError (source "calibrate") for a log of another joint count, or too short for
// two bootstrap blocks.
UnitCalibration CalibrateUnit(const RobotConfig& nominal, double control_dt_s,
                              const std::vector<std::vector<JointSignals>>& ticks, const CalibrationOptions& options);

// The parameter `key` of `joint` (nullptr if absent).
const CalibratedParameter* FindParameter(const JointCalibration& joint, const std::string& key);

}  // namespace armfault
