#include "core/plant/motion/controller.h"

#include <algorithm>
#include <cmath>

#include "core/plant/drive/encoder.h"

namespace armfault {

ControllerConstants MakeControllerConstants(const ModuleParams& m) {
  ControllerConstants c;
  c.p = m.controller;
  c.dt_s = 1.0 / m.controller.rate_Hz;
  c.ratio = m.drive.ratio;
  c.torque_sensor = m.torque_sensor.present;
  c.link_rad_per_count = EncoderRadPerCount(m.encoder) / m.drive.ratio;
  // The thesis's coefficients (0.04762, 0.9048 at 50 rad/s, 500 Hz): pole exp(-w T),
  // input taps averaging two samples with unit DC gain.
  c.filter_a1 = std::exp(-m.controller.torque_filter_rad_s * c.dt_s);
  c.filter_b0 = 0.5 * (1.0 - c.filter_a1);
  c.amps_per_volt = m.inverter.current_per_volt_A_per_V;
  c.command_limit_A = m.inverter.command_limit_A;
  return c;
}

void StepController(const ControllerConstants& c, const ControllerInputs& in, ControllerState* s,
                    ControllerOutputs* out) {
  const ControllerParams& p = c.p;
  const int window = std::min(static_cast<int>(p.velocity_window), kMaxVelocityWindow);
  const int size = kMaxVelocityWindow + 1;

  // Adaptive backward difference: the shortest window (1..window ticks back) over which the
  // count moved by at least velocity_min_counts; fine at speed, averaging at low speed.
  double velocity = 0.0;
  for (int n = 1; n <= std::min(window, s->filled); ++n) {
    const int64_t past = s->counts[(s->head - n + size) % size];
    const int64_t diff = in.encoder_count - past;
    if (std::llabs(diff) >= static_cast<int64_t>(p.velocity_min_counts) || n == std::min(window, s->filled)) {
      velocity = static_cast<double>(diff) * c.link_rad_per_count / (n * c.dt_s);
      break;
    }
  }
  s->counts[s->head] = in.encoder_count;
  s->head = (s->head + 1) % size;
  s->filled = std::min(s->filled + 1, size - 1);

  const double position = static_cast<double>(in.encoder_count) * c.link_rad_per_count;
  const TrajectoryPoint& ref = in.reference;
  const double ev = velocity - ref.qd_rad_s;
  const double ep = position - ref.q_rad;
  const double r = ev + p.lambda_per_s * ep;
  const double a = ref.qdd_rad_s2 - 2.0 * p.lambda_per_s * ev - p.lambda_per_s * p.lambda_per_s * ep;

  const double w = velocity;
  const double sign = w > 0 ? 1.0 : (w < 0 ? -1.0 : 0.0);
  const double stribeck = std::exp(-p.ft_hat * w * w);
  const double nominal = p.im_hat_kg_m2 * c.ratio * a + p.b_hat * w + (p.fc_hat_Nm + p.fs_hat_Nm * stribeck) * sign;

  const std::array<double, 4> y = {w, sign, stribeck * sign, -p.fs_hat_Nm * w * w * stribeck * sign};
  double adaptive = 0.0;
  for (int k = 0; k < 4; ++k) {
    if (s->started) s->regressor_sums[k] += r * y[k] * c.dt_s;
    adaptive += s->regressor_sums[k] * y[k];
  }
  adaptive *= -p.kp_adaptive;
  const double robust = -p.ku_robust_Nm * r / std::max(std::fabs(r), p.epsilon_robust);

  // Torque-sensor feedback through the first-order low-pass (thesis: 50 rad/s at 500 Hz).
  const double x_prev = s->started ? s->torque_in_prev : in.torque_reading_Nm;
  const double y_prev = s->started ? s->torque_out_prev : in.torque_reading_Nm;
  const double torque_filtered = c.filter_b0 * (in.torque_reading_Nm + x_prev) + c.filter_a1 * y_prev;
  s->torque_in_prev = in.torque_reading_Nm;
  s->torque_out_prev = torque_filtered;
  s->started = true;

  const double feedforward = c.torque_sensor ? torque_filtered : in.model_torque_Nm;
  const double request = (nominal + robust + adaptive) / p.kt_hat_Nm_per_A +
                         feedforward / (c.ratio * p.kt_hat_Nm_per_A);
  // DAC: 1.5 V +- request / (A/V), clipped to 0..3 V, 12 bits.
  const double half = 0.5 * c.dac_range_V;
  const double volts = std::clamp(half + request / c.amps_per_volt, 0.0, c.dac_range_V);
  const int code = static_cast<int>(std::lround(volts / c.dac_range_V * c.dac_max_code));
  const double dac_volts = code * c.dac_range_V / c.dac_max_code;
  out->current_command_A = std::clamp((dac_volts - half) * c.amps_per_volt, -c.command_limit_A, c.command_limit_A);
  out->current_request_A = request;
  out->dac_code = code;
  out->position_rad = position;
  out->velocity_rad_s = velocity;
  out->torque_filtered_Nm = feedforward;
}

}  // namespace armfault
