// What the parts of `armfault import` share (import.h is the interface): the JointSignals
// fields and their quantities, the longest run, a run as it is written, and the reading of one
// log into runs. import_map.cc parses and checks the map, import_log.cc reads a log,
// import_run_writer.cc writes a run's signals, import.cc assembles the output directory.
#pragma once

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "campaigns/data/import.h"

namespace armfault::import_detail {

// The JointSignals fields (export column order) and the quantity each is of.
enum class Quantity { kAngle, kAngularVelocity, kTorque, kCurrent, kVoltage, kTemperature };
struct FieldInfo {
  const char* name;
  Quantity quantity;
};
inline constexpr FieldInfo kFields[kImportFields] = {
    {"q_ref_rad", Quantity::kAngle},          {"qd_ref_rad_s", Quantity::kAngularVelocity},
    {"q_meas_rad", Quantity::kAngle},         {"qd_est_rad_s", Quantity::kAngularVelocity},
    {"tau_sensor_Nm", Quantity::kTorque},     {"i_cmd_A", Quantity::kCurrent},
    {"i_supply_meas_A", Quantity::kCurrent},  {"v_bus_meas_V", Quantity::kVoltage},
    {"winding_temp_C", Quantity::kTemperature},
};

// The longest run a campaign holds (campaign_spec.cc's duration_s range): the stand-in
// campaign's duration is the longest run's.
inline constexpr double kMaxRunSeconds = 3600;

inline std::string Quoted(const std::string& s) { return "\"" + s + "\""; }

// One run of a log as written: where it comes from and what it holds.
struct RunOut {
  std::string run_id;
  std::string file;  // the log
  std::string value;  // the run column's value, "" for a whole file
  long first_line = 0, last_line = 0, rows = 0, ticks = 0;
  double end_s = 0;
  std::string signals;  // runs/<case>.csv.gz
};

// Reads the log at `path` by `map` and writes its runs' signals into out_dir/runs/ (named by
// their index in `runs`), at the control period `dt_s` of a robot of `joints` joints. Appends
// each run to `runs` and its run_id to `run_ids` (a run_id already there is an error). Returns
// the data rows read. Throws InputError naming the log, the line and the column.
long ReadLogIntoRuns(const ImportMap& map, const std::string& path, const std::filesystem::path& out_dir, double dt_s,
                     int joints, std::vector<RunOut>* runs, std::set<std::string>* run_ids);

}  // namespace armfault::import_detail
