// `armfault import LOG... --map MAP.json -o DIR`: recorded logs (CSV in any column names and
// units) into the export's layout, so that every tool that takes an export takes an import.
//
// Inputs: CSV logs (plain or gzip), one file per run or one long file split into runs by a
// column; a map (MAP.json) saying which column is which JointSignals field of which joint, in
// which unit, the time column and its unit, the robot, the longest gap accepted and optional
// labels per run. Outputs, as `armfault export` writes them (campaigns/data/export.h):
//   DIR/runs/<case>.csv.gz   t_s, then <field>_j<J> per joint (MonitorSignalChannels), one row
//                            per control tick of the robot (t_s = 0 at the run's first sample),
//                            resampled from the log (ResampleRule below); a field the map does
//                            not name is empty (NaN)
//   DIR/channels.json        the columns' units (ChannelsJson)
//   DIR/manifest.jsonl/.csv  one line per run: run_id, signals, ticks, end_s, the label as a
//                            fault (family, joint, onset_s, magnitude) or none, "label"
//                            ("fault", "healthy" or "unknown") and "source" (file, lines)
//   DIR/campaign.json        a stand-in campaign holding the robot, the longest run's duration
//                            and the map's floors: what `score` and `report` read of a directory
//   DIR/import.json          the map as read, and each log's name, SHA-256 and rows
// Everything is written into a temporary sibling directory that is renamed to DIR at the end:
// any error (InputError naming the file, the 1-based line and the column) leaves nothing.
// docs/import.md.
#pragma once

#include <array>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/plant/robot/robot_config.h"

namespace armfault {

// The JointSignals fields in export column order (SignalColumnNames without units' suffixes
// is the same list): q_ref_rad, qd_ref_rad_s, q_meas_rad, qd_est_rad_s, tau_sensor_Nm, i_cmd_A,
// i_supply_meas_A, v_bus_meas_V, winding_temp_C.
constexpr int kImportFields = 9;

// One log column mapped to a field: SI value = raw * scale + offset, where a unit sets scale
// and offset (UnitToSi) or they are given as numbers.
struct ImportColumn {
  std::string column;  // the log's column name
  std::string unit;    // as given; "" when scale and offset are given instead
  double scale = 1, offset = 0;
  bool hold = false;   // "resample": "hold" (sample and hold); default linear interpolation
};

struct ImportLabel {
  enum class Kind { kUnknown, kHealthy, kFault };
  Kind kind = Kind::kUnknown;
  std::string family;
  int joint = 0;
  double onset_s = 0;  // seconds from the run's first sample (its t_s = 0)
  std::optional<double> magnitude;
  std::string pointer;  // where in the map ("/labels/<run>"), for errors found against the log
};

struct ImportMap {
  std::string source = "<map>";  // the map's path, for errors
  std::string base_dir = ".";    // a robot or URDF file is read relative to it
  std::string name = "import";   // the stand-in campaign's name
  nlohmann::json robot_given;    // as given
  RobotConfig robot;
  ImportColumn time;             // unit s, ms or us (scale only)
  std::string run_column;        // "": one run per file
  double max_gap_periods = 5;    // longest accepted interval between samples, in control periods
  nlohmann::json floors = nlohmann::json::object();  // passed to the stand-in campaign
  // joints[j - 1][field]: the column of that field of joint j, if the map names one.
  std::vector<std::array<std::optional<ImportColumn>, kImportFields>> joints;
  std::map<std::string, ImportLabel> labels;  // by run_id
};

// The factor and offset from `unit` to the SI unit of `field` (0..8): deg -> rad is pi/180;
// false when the unit is unknown or of another quantity (`*known` then lists the field's
// units, for the message).
bool UnitToSi(int field, const std::string& unit, double* scale, double* offset, std::string* known);
// s, ms, us: seconds per unit; false when unknown.
bool TimeUnitToSeconds(const std::string& unit, double* seconds);

// Parses MAP.json's object strictly (unknown keys rejected with their JSON pointer and the
// nearest known key); every error names `source`, the pointer and the value. Reads the robot
// (a preset, a robot JSON file or a URDF robot, relative to `base_dir`).
ImportMap ImportMapFromJson(const nlohmann::json& value, const std::string& source, const std::string& base_dir);
// What needs the robot and the family table: joints within the robot, at least one column,
// labels (a registered family with "did you mean", a joint, onset >= 0, the magnitude in the
// family's range), a gap limit >= 1 period, no column named twice. Throws every error at once.
void ValidateImportMap(const ImportMap& map);
// ReadJsonFile + ImportMapFromJson + ValidateImportMap.
ImportMap ReadImportMap(const std::string& path);

struct ImportOptions {
  std::string output_dir;
  std::function<void(long rows)> progress;  // optional, after each file
};
struct ImportResult {
  long runs = 0;
  long rows = 0;   // data rows read (all files)
  long ticks = 0;  // control ticks written
  double max_end_s = 0;
};
// Imports `logs` by `map` into options.output_dir (which must not exist or be empty). Throws
// InputError (nothing left behind) on any error in a log.
ImportResult ImportLogs(const std::vector<std::string>& logs, const ImportMap& map, const ImportOptions& options);

}  // namespace armfault
