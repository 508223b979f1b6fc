// Times one run's monitor calls (Observe per tick, Finish once): what the monitor under test
// costs, for monitor_cost.jsonl (campaigns/running/monitor_cost.h). The run pipeline holds one per run
// (campaigns/running/run_pipeline.h); scoring's tap and the plant are not timed.
//
// The ticks' times are kept as a histogram, not one by one, so that a run's clock holds the
// same memory however long the run: a bin per float value with its low 13 mantissa
// bits cleared (10 bits left: a bin is 1/1024 of its octave wide), so the median and the 99th
// percentile are exact to 0.1 % (the bin's middle is reported); the mean and the maximum are
// exact. The bins in use are bounded by the octaves a tick's time spans (1024 per octave).
#pragma once

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdint>
#include <map>

namespace armfault {

class MonitorClock {
 public:
  void Start() { start_ = std::chrono::steady_clock::now(); }
  void StopTick() { Add(Elapsed()); }
  void StopFinish() { finish_us_ = Elapsed(); }
  // A tick that took `us` (what StopTick adds; tests give their own).
  void Add(float us);
  // Histogram bins in use: bounded by the range of the ticks' times, not by their number.
  size_t bins() const { return bins_.size(); }
  // {"ticks", "mean_us", "median_us", "p99_us", "max_us", "finish_us"}; null statistics when
  // there was no tick.
  nlohmann::json ToJson() const;

 private:
  float Elapsed() const {
    return std::chrono::duration<float, std::micro>(std::chrono::steady_clock::now() - start_).count();
  }
  // The middle of the histogram's bin holding the tick of rank `k` (0-based, in time order).
  double ValueAtRank(long k) const;
  std::chrono::steady_clock::time_point start_;
  std::map<uint32_t, long> bins_;  // float bits >> kDroppedBits -> ticks
  long ticks_ = 0;
  double total_us_ = 0;
  float max_us_ = 0;
  float finish_us_ = 0;
};

// Microseconds rounded to 1 ns: the clock says no more.
double RoundedUs(double us);

}  // namespace armfault
