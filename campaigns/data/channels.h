// channels.json: what each column of a CSV of signals is, written beside every such CSV that
// armfault writes (a trace, an export's runs/*.csv.gz), so that a reader need not guess units or
// whether a column is what the controller saw or the simulator's truth.
//
// One naming scheme for every signal column: <quantity>_<unit>, then _j<joint> for a joint's
// column (joint 1 = base): "t_s", "q_ref_rad_j1", "tau_sensor_Nm_j3", "brake_engaged_j2" (a 0/1
// flag has no unit in its name). docs/trace-format.md, "Column names and channels.json".
//
// channels.json:
//   {"file": <the CSV's name, or "runs/*.csv.gz">,
//    "channels": [{"name", "quantity", "unit", "source", "joint", "description"}, ...]}
// in column order; "source" is "sensor" (what the joint's controller, and so a monitor, reads),
// "truth" (the simulator's state, which no monitor sees) or "monitor" (a monitor's output);
// "joint" is null for a column of the whole arm (t_s); "unit" is "0/1" for a flag.
#pragma once

#include <string>
#include <vector>

namespace armfault {

struct Channel {
  std::string quantity;     // "q_ref_rad": the name without its joint suffix
  std::string unit;         // "rad", "N m", "0/1"
  std::string source;       // "sensor", "truth" or "monitor"
  std::string description;  // one line, for people
  int joint = 0;            // 1-based; 0: not a joint's column
  std::string Name() const { return joint ? quantity + "_j" + std::to_string(joint) : quantity; }
};

// The per-joint channels `quantities` repeated for joints 1..joints (joint-major: every
// quantity of joint 1, then of joint 2, ...), after `leading` (t_s).
std::vector<Channel> ExpandPerJoint(const std::vector<Channel>& leading, const std::vector<Channel>& quantities,
                                    int joints);
// The CSV header line (with its newline) of `channels`.
std::string ChannelsCsvHeader(const std::vector<Channel>& channels);
// channels.json's text (with its newline); `file` names the CSV it describes.
std::string ChannelsJson(const std::vector<Channel>& channels, const std::string& file);
// The sidecar's path for a CSV at `csv_path`: "out/trace.csv" -> "out/trace.channels.json"
// (a trace's; an export directory has one "channels.json" for all its runs).
std::string ChannelsSidecarPath(const std::string& csv_path);

// What a monitor reads of a run (JointSignals), as `armfault export` writes it per run:
// t_s, then per joint q_ref_rad, qd_ref_rad_s, q_meas_rad, qd_est_rad_s, tau_sensor_Nm, i_cmd_A,
// i_supply_meas_A, v_bus_meas_V, winding_temp_C.
std::vector<Channel> MonitorSignalChannels(int joints);

}  // namespace armfault
