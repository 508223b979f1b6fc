// Writes a run's time series as CSV: one row per controller tick, a header, SI units
// (angles rad, velocities rad/s, torques N m, currents A, voltages V, powers W; the column
// list is in docs/trace-format.md). Attach Observer() to Simulate().
#pragma once

#include <functional>
#include <ostream>
#include <string_view>
#include <vector>

#include "core/plant/simulation.h"

namespace armfault {

class TraceCsvWriter {
 public:
  // Each piece of text (the header, then one line per tick) goes to `sink`.
  TraceCsvWriter(std::function<void(std::string_view)> sink, int joint_count);
  TraceCsvWriter(std::ostream* out, int joint_count);
  void Write(const Tick& tick);
  TickObserver Observer() {
    return [this](const Tick& tick) { Write(tick); };
  }

 private:
  std::function<void(std::string_view)> sink_;
};

// The column names, in order, for `joint_count` joints ("t", then per joint "q_ref_1", ...).
std::vector<std::string> TraceCsvColumns(int joint_count);

}  // namespace armfault
