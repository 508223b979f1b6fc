#include "campaigns/monitor_clock.h"

#include <algorithm>
#include <cmath>

namespace armfault {

namespace {

// Nearest rank: the sorted value at index ceil(q n) - 1, as summary.json's latency p95.
double Quantile(std::vector<float> v, double q) {
  const size_t n = v.size();
  const size_t k = static_cast<size_t>(std::ceil(q * static_cast<double>(n))) - 1;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

}  // namespace

double RoundedUs(double us) { return std::round(us * 1e3) / 1e3; }

nlohmann::json MonitorClock::ToJson() const {
  const long n = static_cast<long>(ticks_us_.size());
  if (n == 0) {
    return {{"ticks", 0}, {"mean_us", nullptr}, {"median_us", nullptr}, {"p99_us", nullptr}, {"max_us", nullptr},
            {"finish_us", RoundedUs(finish_us_)}};
  }
  double total = 0;
  for (float t : ticks_us_) total += t;
  return {{"ticks", n},
          {"mean_us", RoundedUs(total / static_cast<double>(n))},
          {"median_us", RoundedUs(Quantile(ticks_us_, 0.5))},
          {"p99_us", RoundedUs(Quantile(ticks_us_, 0.99))},
          {"max_us", RoundedUs(*std::max_element(ticks_us_.begin(), ticks_us_.end()))},
          {"finish_us", RoundedUs(finish_us_)}};
}

}  // namespace armfault
