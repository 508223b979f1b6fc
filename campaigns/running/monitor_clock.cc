#include "campaigns/running/monitor_clock.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace armfault {

namespace {

constexpr int kDroppedBits = 13;  // of a float's 23 mantissa bits

// Nearest rank: the index ceil(q n) - 1 of the sorted values, as summary.json's latency p95.
long RankOf(long n, double q) { return static_cast<long>(std::ceil(q * static_cast<double>(n))) - 1; }

}  // namespace

double RoundedUs(double us) { return std::round(us * 1e3) / 1e3; }

void MonitorClock::Add(float us) {
  us = std::max(us, 0.0f);
  uint32_t bits;
  std::memcpy(&bits, &us, sizeof bits);
  ++bins_[bits >> kDroppedBits];
  ++ticks_;
  total_us_ += us;
  max_us_ = std::max(max_us_, us);
}

double MonitorClock::ValueAtRank(long k) const {
  long seen = 0;
  for (const auto& [key, count] : bins_) {
    seen += count;
    if (seen <= k) continue;
    const uint32_t low = key << kDroppedBits, high = low | ((1u << kDroppedBits) - 1);
    float a, b;
    std::memcpy(&a, &low, sizeof a);
    std::memcpy(&b, &high, sizeof b);
    return std::min(0.5 * (static_cast<double>(a) + static_cast<double>(b)), static_cast<double>(max_us_));
  }
  return max_us_;
}

nlohmann::json MonitorClock::ToJson() const {
  const long n = ticks_;
  if (n == 0) {
    return {{"ticks", 0}, {"mean_us", nullptr}, {"median_us", nullptr}, {"p99_us", nullptr}, {"max_us", nullptr},
            {"finish_us", RoundedUs(finish_us_)}};
  }
  return {{"ticks", n},
          {"mean_us", RoundedUs(total_us_ / static_cast<double>(n))},
          {"median_us", RoundedUs(ValueAtRank(RankOf(n, 0.5)))},
          {"p99_us", RoundedUs(ValueAtRank(RankOf(n, 0.99)))},
          {"max_us", RoundedUs(max_us_)},
          {"finish_us", RoundedUs(finish_us_)}};
}

}  // namespace armfault
