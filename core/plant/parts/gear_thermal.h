// The strain-wave gear's thermal side: a gearbox thermal node beside the winding's,
// the lubricant's viscosity law that scales the joint friction with the gearbox temperature,
// and the torque sensor's thermal drift (the sensor sits on the gear output, so the gearbox
// node sets its temperature). Off unless a drive gives its "gearbox" group (ModuleParams::gearbox,
// GearboxParams::present): without it the plant is today's, bit for bit.
//
// Thermal network (first-order R-C nodes, explicit Euler at the physics step, as the winding's):
//   C_w dT_w/dt = P_copper           - (T_w - T_amb)/R_w - G_wg (T_w - T_g)     (winding)
//   C_g dT_g/dt = P_friction(prev)   - (T_g - T_amb)/R_g + G_wg (T_w - T_g)     (gearbox)
// with C = tau / R (MotorParams thermal_*, GearboxParams thermal_*), G_wg the conductance from
// the winding to the gearbox. P_friction is the friction power of the previous physics step
// dissipated in the joint (viscous, Coulomb/Stribeck, mesh and load-dependent loss; not the
// brake's share): the step's own is known only after ODE has solved it.
//
// Lubricant law (Vogel): the friction of the gear and bearings scales with
//   f(T) = exp(B/(T - C) - B/(T_ref - C))          [T, C, T_ref in deg C, B in K]
// so that f(T_ref) = 1 (the FrictionParams are the values at T_ref): the viscous coefficient b
// by f(T), the no-load running (Coulomb and Stribeck) torques by f(T)^n (n: coulomb_exponent),
// the Coulomb part being boundary friction that viscosity moves less. Values and their
// sources: docs/assumptions.md, "Gearbox temperature, load and sensor drift".
//
// Torque sensor drift: the amplifier sees
//   (1 + gain_error + k_gain (T_g - T_ref)) tau + offset_error + k_offset (T_g - T_ref).
#pragma once

namespace armfault {

struct GearboxParams {
  bool present = false;  // the drive gives a "gearbox" group; absent: all of the below is off
  // Gearbox thermal node.
  double thermal_resistance_K_per_W = 2.0;  // gearbox housing to ambient, R_g
  double thermal_time_constant_s = 2400;    // R_g C_g
  double winding_coupling_W_per_K = 0.0;    // G_wg, winding to gearbox (0: the nodes are independent)
  // Lubricant (Vogel) law; FrictionParams are the values at reference_C.
  double reference_C = 20;
  double vogel_B_K = 0;                     // 0: friction independent of temperature
  double vogel_C_C = -100;
  double coulomb_exponent = 0.5;            // Coulomb/Stribeck scale with f^n, viscous with f
  // Load-dependent friction of the strain-wave gear (core/plant/parts/load_friction.h): motor-side
  // dry friction += mu |tau_transmitted| / ratio, mu by the direction of power flow.
  double load_friction_driving = 0;         // motor drives the link (tau qd > 0)
  double load_friction_backdriven = 0;      // the link drives the motor (tau qd < 0)
  // Torque sensor thermal drift, relative to reference_C (the sensor's calibration).
  double sensor_offset_Nm_per_K = 0;
  double sensor_gain_per_K = 0;
  // The duty a "warm" start assumes (RunSpec::start): the nodes start at the steady state of
  // these constant losses (WarmSteadyState).
  double warm_copper_loss_W = 0;
  double warm_friction_loss_W = 0;
};

// f(T) of the Vogel law above (1 at reference_C; 1 when vogel_B_K = 0). Needs T > vogel_C_C.
double LubricantFactor(const GearboxParams& p, double temperature_C);

// The two nodes' temperatures [deg C].
struct ThermalNodes {
  double winding_C = 20;
  double gear_C = 20;
};

// One explicit Euler step of dt [s] of the network above (winding: R_w = winding_R_K_per_W,
// tau_w = winding_tau_s; R_w = 0 pins the winding at ambient, as today's node does).
void StepThermalNodes(double winding_R_K_per_W, double winding_tau_s, const GearboxParams& p, double ambient_C,
                      double p_copper_W, double p_friction_W, double dt_s, ThermalNodes* nodes);

// The network's steady state under constant losses p_copper_W (winding) and p_friction_W
// (gearbox): solves  x/R_w + G (x - y) = P_c,  y/R_g - G (x - y) = P_f  for the rises x, y over
// ambient. Without coupling: T_g = T_amb + R_g P_f and T_w = T_amb + R_w P_c.
ThermalNodes SteadyThermalNodes(double winding_R_K_per_W, const GearboxParams& p, double ambient_C,
                                double p_copper_W, double p_friction_W);

// The "warm" start: SteadyThermalNodes at the drive's stated duty (warm_copper_loss_W,
// warm_friction_loss_W); at ambient when the drive has no gearbox group.
ThermalNodes WarmSteadyState(double winding_R_K_per_W, const GearboxParams& p, double ambient_C);

// The torque the sensor's amplifier sees [N m] for a true torque tau_Nm at gearbox temperature
// gear_C, with the unit's gain and offset errors (TorqueSensorParams gain_error, offset_error_Nm).
double DriftedSensorInputNm(const GearboxParams& p, double gear_C, double gain_error, double offset_error_Nm,
                            double tau_Nm);

}  // namespace armfault
