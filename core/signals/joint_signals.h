// The port between the plant and the monitors: what one joint's controller has at a tick.
// The plant fills it (JointTick::signals, core/plant/simulation.h); a monitor reads it and
// nothing else (HealthMonitor::Observe, core/monitors/monitor.h). Neither side includes the
// other for it, so what a monitor may see is fixed here, in one place.
// The plugin C ABI mirrors it field for field (include/armfault/monitor_plugin.h).
#pragma once

#include <limits>

namespace armfault {

// The signals one joint's controller has at a tick, and nothing else: a monitor never sees
// the simulator's truth. Units: rad, rad/s, N m, A, V, °C.
struct JointSignals {
  double q_ref_rad = 0, qd_ref_rad_s = 0;  // reference the controller tracks
  double q_meas_rad = 0;                   // encoder (link side)
  double qd_est_rad_s = 0;                 // controller's velocity estimate
  double tau_sensor_Nm = 0;                // joint torque sensor (after the ADC); NaN on a joint without one
  double i_cmd_A = 0;                      // commanded current (after the DAC)
  double i_supply_meas_A = 0;              // driver input current, mean over the control period, with noise
  double v_bus_meas_V = 0;                 // driver input (bus) voltage
  // winding temperature sensor, only where the robot config declares one; NaN otherwise
  double winding_temp_C = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace armfault
