// Writes a run's time series as CSV: one row per controller tick, a header, SI units
// (angles rad, velocities rad/s, torques N m, currents A, voltages V, powers W; the column
// list is in docs/trace-format.md; each name ends in its unit and joint, "tau_sensor_Nm_j3").
// Attach Observer() to Simulate().
#pragma once

#include <functional>
#include <ostream>
#include <string_view>
#include <vector>

#include "campaigns/data/channels.h"
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

// The columns, in order, for `joint_count` joints: "t_s", then per joint "q_ref_rad_j1", ...
// (campaigns/data/channels.h: the names `armfault export` uses, with units); what channels.json
// beside the trace describes.
std::vector<Channel> TraceCsvChannels(int joint_count);
std::vector<std::string> TraceCsvColumns(int joint_count);  // their names
// Writes the channels.json of a trace written to `csv_path` beside it (ChannelsSidecarPath:
// "trace.csv" -> "trace.channels.json"), atomically.
void WriteTraceChannels(const std::string& csv_path, int joint_count);

}  // namespace armfault
