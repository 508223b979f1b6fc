// Brushless DC motor with its inverter (driver power stage) and current loop, thesis
// eq 4-1 ... 4-3 and 4-9 ... 4-13.
//
// Motor: three phases in star, per phase  v_x - v_n = R i_x + L di_x/dt + e_x,  sum i_x = 0,
// trapezoidal back-EMF e_x = (K_T/2) omega_m F(theta_e - 2 pi k/3), F in [-1, 1] with flat
// tops over 120 electrical degrees; torque T_e = sum e_x i_x / omega_m = (K_T/2) sum F_x i_x,
// so two conducting phases carrying I give T_e = K_T I (stall torque K_T x current).
//
// Inverter: six-step commutation from the rotor angle (ideal Hall sensors); the conducting
// pair is driven by complementary PWM (averaged: leg voltages (U_d +- u)/2), the third leg is
// off and freewheels through its diodes until its current dies out. A signed PI current loop
// makes the current into the sector's positive-EMF phase follow i_cmd (u may be negative: a
// negative command drives the current the other way through the same pair, so the loop's
// integral, which carries the back-EMF voltage, is continuous through a sign change).
//
// Inputs per physics step: commanded current [A], enable flag, motor angle [rad] and speed
// [rad/s] (speed held over the step), bus voltage, the hardware condition.
// Outputs: mean electromagnetic torque [N m] and the power terms [W] of the step:
//   p_supply = p_copper + p_emf + p_magnetic + p_inverter + p_quiescent  (energy balance),
// with p_supply computed from the bus side (leg voltages x leg currents + losses).
//
// Integration: per electrical sub-step (the PWM period), the exact solution of the linear RL
// network for the leg voltages the PI loop set at its start (exp(-R h / L)); a freewheeling
// current that would reverse is stopped at its zero crossing. On almost every sub-step only the
// sector's pair conducts (one series current, back-EMF 2 (K_T/2) omega on the plateaus): those
// run in a tight loop of their own (RunSector in motor.cc) that keeps the state in registers and
// does the same operations in the same order as one sub-step at a time.
#pragma once

#include <array>

#include "core/plant/parts/hardware_condition.h"
#include "core/plant/robot/robot_config.h"

namespace armfault {

// Constants of one drive derived once for a given electrical sub-step.
struct DriveConstants {
  double substep_s = 0;
  double kt_Nm_per_A = 0;
  double resistance_ohm = 0;
  double inductance_H = 0;
  double pole_pairs = 0;
  double decay = 0;        // exp(-R h / L), healthy winding
  double kp_V_per_A = 0;   // PI current loop on the line (two phases in series: 2R, 2L)
  double ki_V_per_A_s = 0;
  InverterParams inverter;
};
DriveConstants MakeDriveConstants(const ModuleParams& module, double substep_s);

struct DriveState {
  std::array<double, 3> phase_current_A{};
  double pi_integral_V = 0;
  bool tripped = false;  // over-current protection has opened all switches (latched)
};

struct DriveInputs {
  double current_command_A = 0;
  bool enabled = true;
  double motor_angle_rad = 0;
  double motor_speed_rad_s = 0;
};

// Averages over one physics step (powers) and end-of-step values (currents).
struct DriveOutputs {
  double torque_Nm = 0;
  double p_supply_W = 0;
  double p_copper_W = 0;
  double p_emf_W = 0;        // electrical -> mechanical power, T_e omega_m
  double p_magnetic_W = 0;   // rate of change of the energy stored in the windings
  double p_inverter_W = 0;   // switch conduction, switching and diode losses
  double p_quiescent_W = 0;
  double supply_current_A = 0;
  double current_sq_A2 = 0;  // mean of i_a^2 + i_b^2 + i_c^2 (copper loss / R)
  double peak_phase_current_A = 0;
  std::array<double, 3> phase_current_A{};
};

// Trapezoidal back-EMF shape of phase a at electrical angle theta_e [rad]: +1 on
// [30, 150] deg, -1 on [210, 330] deg, linear in between.
double BackEmfShape(double theta_e_rad);

// Advances the drive by `substeps` electrical sub-steps of constants.substep_s.
void StepDrive(const DriveConstants& constants, const HardwareCondition& condition,
               const DriveInputs& inputs, int substeps, DriveState* state, DriveOutputs* out);

}  // namespace armfault
