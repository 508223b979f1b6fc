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

std::array<double, kDetectorCount> SequentialSeScales(const MonitorConfig& c) {
  return {c.kt_se_scale, c.resistance_se_scale, c.friction_factor_se_scale, c.sensor_drift_se_scale};
}

std::array<double, kDetectorCount> SequentialWanders(const MonitorConfig& c) {
  return {c.kt_bias_wander_s, c.resistance_bias_wander_s, c.friction_factor_bias_wander_s,
          c.sensor_drift_bias_wander_s};
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

bool Cusum::Advance(double dt) {
  since_look_s_ += dt;
  // A tick's rounding must not skip a look: a look is due within a microsecond of L.
  if (since_look_s_ + 1e-6 < look_s_) return false;
  since_look_s_ = std::max(0.0, since_look_s_ - look_s_);
  return true;
}

double Cusum::Look(double z) {
  s_ = std::max(0.0, s_ + z - k_);
  return s_;
}

double Cusum::Tick(double dt, double z) {
  if (Advance(dt)) Look(z);
  return s_;
}

BiasFilter::BiasFilter(double bound, double wander_s, double settle_s, double se_scale, bool signed_bias)
    : m_(bound), wander_s_(wander_s), settle_s_(settle_s), scale_(se_scale), signed_(signed_bias), p_(bound * bound) {}

BiasFilter::Innovation BiasFilter::Look(double look_s, double b, double se) {
  const double m2 = m_ * m_;
  // The bias may wander, but its variance never exceeds its bound's: |beta| <= m holds a priori.
  age_s_ += look_s;
  const double prior = age_s_ <= settle_s_ ? m2 : std::min(p_ + m2 * look_s / wander_s_, m2);
  const double r = scale_ * se * scale_ * se;
  const double s = prior + r;
  Innovation in;
  in.nu = b - beta_;
  in.sd = std::sqrt(s);
  const double gain = s > 0 ? prior / s : 0.0;
  beta_ += gain * in.nu;
  p_ = (1.0 - gain) * prior;
  beta_ = std::min(beta_, m_);
  if (signed_) beta_ = std::max(beta_, -m_);
  return in;
}

SequentialTest::SequentialTest(double look_s, double allowance_sd, double bound, double wander_s, double settle_s,
                               double se_scale, bool two_sided)
    : up_(look_s, allowance_sd),
      down_(look_s, allowance_sd),
      bias_(bound, wander_s, settle_s, se_scale, two_sided),
      two_sided_(two_sided) {}

}  // namespace armfault
