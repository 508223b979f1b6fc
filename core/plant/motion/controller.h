// The thesis joint controller (appendix C), one instance per joint, run at rate_Hz with only
// that joint's sensors. Link-side errors e_v = qd_hat - qd_ref, e_p = q_hat - q_ref,
// r = e_v + lambda e_p, a = qdd_ref - 2 lambda e_v - lambda^2 e_p. Motor-side torque terms:
//   nominal  = I_m gamma a + b w + (F_c + F_s exp(-F_t w^2)) sign(w)     (w: link velocity)
//   adaptive u_p = -K_P sum_k S_k Y_k,  S_k += r Y_k dt,  Y = [w, sign w, e sign w, -F_s w^2 e sign w],
//            e = exp(-F_t w^2)
//   robust   u_u = -K_u r / max(|r|, epsilon)
// Command current i = (nominal + u_u + u_p)/K_T + tau_ff / (gamma K_T), sent through
// the 12-bit DAC (0..3 V around 1.5 V) at current_per_volt A/V: +-6 A. The thesis code's
// factor -0.5 is taken as undoing its board's inverting x2 stage (docs/assumptions.md).
// tau_ff: the torque-sensor reading through a first-order low-pass (the thesis); on a joint
// without a torque sensor, the robot model's transmitted torque for every joint's reference
// (core/plant/robot/rigid_body_dynamics.h), as industrial controllers feed forward their model.
// Velocity: adaptive backward difference of encoder counts.
#pragma once

#include <array>
#include <cstdint>

#include "core/plant/robot/robot_config.h"
#include "core/plant/motion/trajectory.h"

namespace armfault {

constexpr int kMaxVelocityWindow = 64;

struct ControllerConstants {
  ControllerParams p;
  double dt_s = 0;
  double ratio = 0;
  bool torque_sensor = true;  // else the feedforward is ControllerInputs::model_torque_Nm
  double link_rad_per_count = 0;
  double filter_b0 = 0, filter_a1 = 0;  // y = b0 (x + x_prev) + a1 y_prev
  double amps_per_volt = 0;
  double command_limit_A = 0;
  double dac_range_V = 3.0;
  int dac_max_code = 4095;
};
ControllerConstants MakeControllerConstants(const ModuleParams& module);

struct ControllerState {
  std::array<int64_t, kMaxVelocityWindow + 1> counts{};  // ring buffer of past counts
  int head = 0;
  int filled = 0;
  std::array<double, 4> regressor_sums{};
  double torque_in_prev = 0, torque_out_prev = 0;
  bool started = false;
};

struct ControllerInputs {
  int64_t encoder_count = 0;
  double torque_reading_Nm = 0;
  double model_torque_Nm = 0;  // without a torque sensor: the model's torque for the reference [N m, link side]
  TrajectoryPoint reference;
};

struct ControllerOutputs {
  double current_command_A = 0;  // what the driver receives after the DAC
  double current_request_A = 0;  // before DAC clipping and quantisation
  int dac_code = 0;
  double position_rad = 0;       // link side, from the encoder
  double velocity_rad_s = 0;     // link side, estimated
  double torque_filtered_Nm = 0;  // the feedforward tau_ff
};

void StepController(const ControllerConstants& c, const ControllerInputs& in, ControllerState* s,
                    ControllerOutputs* out);

}  // namespace armfault
