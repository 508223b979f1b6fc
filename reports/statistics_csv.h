// Writes every statistic a monitor publishes, at every tick and for every joint, beside its
// threshold, as CSV (`armfault trace --run RUN --statistics FILE`, docs/trace-format.md,
// "Statistics CSV"). Long format, one row per tick, joint and statistic, in that order:
//   t_s        the tick's time [s]
//   joint      1-based
//   statistic  its name as the monitor declares it ("kt_deficit"; the built-in monitor's
//              "<parameter>_deviation" and "<parameter>_significance")
//   family     the fault family its alarm names (or "unknown")
//   value      the statistic's value after the tick, in the statistic's own unit (empty: none)
//   threshold  the threshold the monitor runs with
//   above      1 when value passes the threshold (value > threshold; >= for an inclusive
//              statistic, the built-in significance), 0 when not, empty without a value
// Numbers in their shortest exact form, so a file of the same run is byte-identical. A monitor
// that publishes no statistic gives the header alone.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "core/monitors/monitor.h"

namespace armfault {

class StatisticsCsvWriter : public StatisticsObserver {
 public:
  // Each piece of text (the header, then each tick's rows) goes to `sink`.
  explicit StatisticsCsvWriter(std::function<void(std::string_view)> sink);
  void Declare(const std::vector<PublishedStatistic>& statistics, int joints) override;
  void Values(double t_s, const double* values) override;
  // The statistics declared (empty until Declare, or for a monitor that publishes none).
  const std::vector<PublishedStatistic>& statistics() const { return statistics_; }
  // Whether Declare was called (the header is written).
  bool declared() const { return header_written_; }

 private:
  std::function<void(std::string_view)> sink_;
  std::vector<PublishedStatistic> statistics_;
  std::vector<std::string> fixed_;  // per statistic: ",name,family," for the rows
  std::vector<std::string> thresholds_;
  int joints_ = 0;
  bool header_written_ = false;
  std::string line_;
};

// The header line's columns, in order.
std::vector<std::string> StatisticsCsvColumns();

}  // namespace armfault
