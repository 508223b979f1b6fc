#include "core/monitors/tick_detectors.h"

#include <algorithm>
#include <cmath>

namespace armfault {

TickTerms TermsOf(const MonitorConfig& c, const JointKnowledge& k, const JointSignals& now, const JointSignals& prev,
                  double dt_s) {
  TickTerms x;
  x.dq = now.q_meas_rad - prev.q_meas_rad;
  x.i = prev.i_cmd_A;
  x.tau_mean = 0.5 * (now.tau_sensor_Nm + prev.tau_sensor_Nm);
  const bool has_temp = std::isfinite(now.winding_temp_C);
  const double dT = has_temp ? now.winding_temp_C - k.electrical.reference_temp_C : 0.0;
  const double kt_scale = 1.0 - c.magnet_kt_loss_per_K * dT;
  x.rotor_torque = kt_scale * k.ratio * k.kt_Nm_per_A * x.i;
  x.p_supply = now.v_bus_meas_V * now.i_supply_meas_A;
  x.p_rotor = k.electrical.rotor_gain * x.rotor_torque * x.dq / dt_s;
  x.p_copper = (1.0 + c.copper_resistance_per_K * dT) * k.electrical.Copper(x.i);
  x.p_fixed = k.electrical.Fixed(x.i);
  if (has_temp) x.winding_above_K = dT;
  return x;
}

Candidate TickDetectors::Update(const MonitorConfig& c, const JointKnowledge& k, const TickTerms& x,
                                const JointSignals& now, const JointSignals& prev, int dir, double dt) {
  Candidate structural;
  // Inverter short: supply power far above what the commanded current can explain.
  const double excess = x.p_supply - (std::max(0.0, x.p_rotor) + x.p_copper + x.p_fixed);
  overpower_s = excess > c.overpower_W ? overpower_s + dt : 0.0;
  // Dead drive: a large command but no copper loss in the supply: the over-current protection
  // has opened the bridge (a short that tripped faster than it could be seen). A joint
  // back-driven by its load returns rotor power to the bus, which pays part of the copper loss:
  // that part is no evidence of an open bridge.
  const double expected_draw = x.p_copper + std::min(0.0, x.p_rotor);
  const bool dead = std::fabs(x.i) >= c.dead_drive_current_A && expected_draw > 0 &&
                    x.p_supply - k.electrical.quiescent_W < c.dead_drive_draw_fraction * expected_draw;
  dead_s = dead ? dead_s + dt : 0.0;
  // Stuck torque sensor: on a rail, or unchanged while the joint moves and the commanded
  // torque swings (a live sensor would follow it).
  const bool on_rail = k.torque_sensor && (now.tau_sensor_Nm >= k.sensor_max_Nm - 1e-9 || now.tau_sensor_Nm <= k.sensor_min_Nm + 1e-9);
  // Saturation against a stuck lead: a torque beyond the range reaches the rail at the rate the
  // load changes, so the reading just before is close to it; a supply or ground lead throws it
  // there in one tick. A stretch reached gradually is saturation: no evidence either way.
  if (on_rail && rail_s == 0) {
    const bool was_on_rail = prev.tau_sensor_Nm >= k.sensor_max_Nm - 1e-9 || prev.tau_sensor_Nm <= k.sensor_min_Nm + 1e-9;
    const double jump = std::fabs(now.tau_sensor_Nm - prev.tau_sensor_Nm);
    rail_saturated = !was_on_rail && jump <= c.rail_jump_fraction * (k.sensor_max_Nm - k.sensor_min_Nm);
  }
  rail_s = on_rail ? rail_s + dt : 0.0;
  if (!on_rail) rail_saturated = false;
  if (k.torque_sensor && now.tau_sensor_Nm == prev.tau_sensor_Nm) {
    if (flat_s == 0) {
      flat_cmd_min = flat_cmd_max = x.rotor_torque, flat_dq = 0;
      flat_ref_min = flat_ref_max = now.q_ref_rad;
    }
    flat_s += dt;
    flat_dq += std::fabs(x.dq);
    flat_ref_min = std::min(flat_ref_min, now.q_ref_rad);
    flat_ref_max = std::max(flat_ref_max, now.q_ref_rad);
    flat_cmd_min = std::min(flat_cmd_min, x.rotor_torque);
    flat_cmd_max = std::max(flat_cmd_max, x.rotor_torque);
  } else {
    flat_s = 0;
  }
  // The joint moved, or was meant to stay put: a command swinging against a still reference is
  // the load (the other joints) changing, which a live sensor follows; a brake fighting a moving
  // reference is not that.
  const bool flat_stuck = flat_s >= c.stuck_time_s && flat_cmd_max - flat_cmd_min >= c.stuck_torque_span_Nm &&
                          (flat_dq >= 10 * c.rest_velocity_rad_s * c.stuck_time_s ||
                           flat_ref_max - flat_ref_min < c.blocked_error_rad);
  // Locked: at rest, far from a moving reference, with high current.
  const bool blocked = dir == 0 && std::fabs(now.i_cmd_A) >= c.blocked_current_A &&
                       std::fabs(now.q_ref_rad - now.q_meas_rad) >= c.blocked_error_rad;
  blocked_s = blocked ? blocked_s + dt : 0.0;

  if (overpower_s >= c.overpower_time_s) {
    structural = {HealthState::kDefective, "inverter_short", "excess_power_W", excess, 1.0, true};
  } else if (dead_s >= c.dead_drive_time_s) {
    structural = {HealthState::kDefective, "inverter_short", "", 0, 1.0, true};
  } else if (!rail_saturated && (rail_s >= c.rail_time_s || flat_stuck)) {
    structural = {HealthState::kDefective, "torque_sensor_stuck", "stuck_reading_Nm", now.tau_sensor_Nm, 1.0, true};
  } else if (blocked_s >= c.blocked_time_s) {
    const double motor = std::fabs(k.ratio * k.kt_Nm_per_A * now.i_cmd_A);
    if (std::fabs(now.tau_sensor_Nm) < c.brake_torque_fraction * motor) {
      // The torque stays inside the module: the brake holds it. With the drive at its limit
      // this is a lower bound of the drag.
      const double drag = (motor - std::fabs(now.tau_sensor_Nm)) / (k.ratio * k.brake_holding_Nm);
      structural = {HealthState::kDefective, "brake_lock", "drag_fraction", std::min(1.0, drag), 1.0, true};
    } else {
      structural = {HealthState::kDefective, "unknown", "", 0, 0.5, true};  // blocked outside the joint
    }
  }
  return structural;
}

}  // namespace armfault
