// Times one run's monitor calls (Observe per tick, Finish once): what the monitor under test
// costs, for monitor_cost.jsonl (campaigns/monitor_cost.h). The run pipeline holds one per run
// (campaigns/run_pipeline.h); scoring's tap and the plant are not timed.
#pragma once

#include <nlohmann/json.hpp>

#include <chrono>
#include <vector>

namespace armfault {

class MonitorClock {
 public:
  void Start() { start_ = std::chrono::steady_clock::now(); }
  void StopTick() { ticks_us_.push_back(Elapsed()); }
  void StopFinish() { finish_us_ = Elapsed(); }
  // {"ticks", "mean_us", "median_us", "p99_us", "max_us", "finish_us"}; null statistics when
  // there was no tick.
  nlohmann::json ToJson() const;

 private:
  float Elapsed() const {
    return std::chrono::duration<float, std::micro>(std::chrono::steady_clock::now() - start_).count();
  }
  std::chrono::steady_clock::time_point start_;
  std::vector<float> ticks_us_;
  float finish_us_ = 0;
};

// Microseconds rounded to 1 ns: the clock says no more.
double RoundedUs(double us);

}  // namespace armfault
