#include "core/monitors/sequential_test.h"

#include <algorithm>
#include <cmath>

#include "core/monitors/monitor_config.h"

namespace armfault {

double SiegmundArl(double h, double k) {
  const double x = 2.0 * k * (h + 1.166);
  return (std::exp(x) - x - 1.0) / (2.0 * k * k);
}

double CusumThreshold(double arl_looks, double k) {
  if (!(SiegmundArl(0.0, k) < arl_looks)) return 0.0;
  double lo = 0.0, hi = 1.0;
  while (SiegmundArl(hi, k) < arl_looks && hi < 1e6) hi *= 2.0;
  // ARL0 rises monotonically in h: bisection to well below a statistic quantum.
  for (int i = 0; i < 100 && hi - lo > 1e-9; ++i) {
    const double mid = 0.5 * (lo + hi);
    (SiegmundArl(mid, k) < arl_looks ? lo : hi) = mid;
  }
  return hi;
}

std::array<double, kDetectorCount> SequentialLooks(const MonitorConfig& c) {
  const double m = c.sequential_look_memories;
  return {m * c.electrical_time_constant_s, m * c.electrical_time_constant_s, m * c.balance_time_constant_s,
          m * c.drift_balance_time_constant_s};
}

std::array<double, kDetectorCount> SequentialModelErrors(const MonitorConfig& c) {
  return {c.kt_model_error, c.resistance_model_error, c.friction_factor_model_error, c.sensor_drift_model_error_Nm};
}

int SequentialTestCount(int joints, int sensed) { return 3 * joints + 2 * sensed; }

DetectorThresholds SequentialThresholds(const MonitorConfig& config, int tests, double target_per_hour) {
  const std::array<double, kDetectorCount> looks = SequentialLooks(config);
  DetectorThresholds h{};
  for (int d = 0; d < kDetectorCount; ++d) {
    const double looks_per_hour = 3600.0 / looks[d];
    h[d] = CusumThreshold(looks_per_hour * std::max(1, tests) / target_per_hour, config.sequential_allowance_sd);
  }
  return h;
}

DetectorThresholds SequentialThresholds(const MonitorConfig& config, int tests) {
  return SequentialThresholds(config, tests, config.target_false_alarms_per_hour);
}

double Cusum::Tick(double dt, double z) {
  since_look_s_ += dt;
  // A tick's rounding must not skip a look: a look is due within a microsecond of L.
  if (since_look_s_ + 1e-6 >= look_s_) {
    since_look_s_ = std::max(0.0, since_look_s_ - look_s_);
    s_ = std::max(0.0, s_ + z - k_);
  }
  return s_;
}

}  // namespace armfault
