// A campaign file's settings, parsed and validated: faults swept over magnitudes, onsets,
// joints and trajectories, healthy runs for false-alarm rates, run-to-run variation, the
// monitor's settings and the floors. Every key is in docs/campaign-format.md;
// campaigns/spec/campaign.schema.json is its JSON Schema.
//
// The spec is plain data: nothing is loaded or built from it here (no trajectory CSV file is
// read, no monitor made), so merge, tune and provenance read a run directory's campaign.json
// wherever it is. The cases it expands to are in campaigns/spec/cases.h; what is built for running
// (trajectories loaded, the monitor model) in campaigns/campaign.h.
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "campaigns/spec/confounders.h"
#include "core/base/json_input.h"
#include "core/monitors/registry.h"
#include "core/plant/robot/robot_config.h"
#include "core/plant/motion/trajectory.h"

namespace armfault {

// Values of one key: a list, an inclusive grid {"from","to","steps"}, or {"uniform":[a,b]}
// (drawn per run from the run's seed), or one fixed value.
struct Sweep {
  std::vector<nlohmann::json> values;  // list or grid points (numbers or strings)
  bool uniform = false;
  bool grid = false;    // values came from {"from","to","steps"}
  double low = 0, high = 0;
  std::string pointer;  // of the sweep in the file
  size_t count() const { return uniform ? 1 : values.size(); }
};

struct FaultEntry {
  std::string family;
  std::string pointer;                              // "/faults/1"
  std::vector<int> joints;                          // 1-based
  std::vector<std::pair<std::string, Sweep>> keys;  // every other key, in alphabetical order
  // A compound entry ({"compound": [FAULT, ...], "name": ...}, docs/campaign-format.md,
  // "Compound faults"): family "compound", no joints or keys; its elements act together in
  // one run, each an ordinary fault with single values ({"family", "joint", ...}).
  bool compound = false;
  std::string name;                                 // compound only: its name in run_ids and groups
  std::vector<nlohmann::json> elements;             // compound only
};

// A trajectory as the campaign gives it; what it loads (CSV files) is built for running
// (Campaign::loaded_trajectories, campaigns/spec/campaign.h).
struct CampaignTrajectory {
  std::string name;
  nlohmann::json joints;  // as given (the run file's "joints" object)
};

// The per-joint values a unit draws from its stated tolerances, in this order: relative ones
// multiply the datasheet value by 1 + s (2u - 1), absolute ones (_Nm, _A) add s (2u - 1).
struct ToleranceKey {
  const char* name;                 // key under "tolerances"
  double StatedTolerances::*member;
  bool absolute;
  double max;                       // largest half-width accepted
};
const std::vector<ToleranceKey>& ToleranceKeys();
// The "datasheet" preset: typical catalogue tolerances of this class of drive (docs/assumptions.md).
StatedTolerances DatasheetTolerances();

// Variation between runs; each value is fixed or {"uniform": [a, b]}.
struct Variation {
  Sweep payload_kg;        // added to the robot's payload; empty: none
  Sweep torque_noise_Nm;   // torque-sensor noise (1 sigma); empty: the robot's
  double friction_spread = 0;  // each joint's true friction x U[1 - s, 1 + s]; the monitor keeps nominal
  bool has_tolerances = false;
  StatedTolerances tolerances;  // half-widths a unit draws in (and its datasheet states)
  Sweep ambient_C;         // per run; empty: 20 °C
  // Each run starts warm (RunSpec::start) with this probability, drawn from its seed after the
  // other draws; negative (absent): every run starts cold and nothing is drawn.
  double warm_start_fraction = -1;
  int units = 0;           // a fleet of this many robot units; 0: every run is its own unit
  // Each unit draws its gearbox group and ripple over these ranges (campaigns/spec/confounders.h).
  bool has_confounders = false;
  ConfounderRanges confounders;
};

// One run of a boundary search (`armfault boundary`, campaigns/tuning/boundary.h): fault entry
// `entry` on `joint` along trajectory `trajectory` at the magnitude `magnitude`. `number`
// counts the runs of the same cell (trajectory x entry x joint) before it, from 0.
struct SearchRun {
  size_t trajectory = 0;
  size_t entry = 0;
  int joint = 0;
  double magnitude = 0;
  long number = 0;
};

// The "search" block (docs/campaign-format.md, "Boundary search"): where each cell's detection
// probability crosses `target` with `confidence`, found by batches of runs. Every fault entry
// is searched over its magnitude key (FaultMagnitudeKey) in [range_low, range_high] (the
// entry's own sweep, or "range").
struct SearchEntryRange {
  std::string key;        // the entry's magnitude key ("kt_factor")
  double low = 0, high = 0;
  double tolerance = 0;   // stop when the boundary's interval is at most this wide (magnitude units)
  double lattice = 0;     // magnitudes are rounded to multiples of this
};
struct SearchSpec {
  bool present = false;
  double target = 0.9;
  double confidence = 0.95;
  int batch = 8;          // runs per cell and batch (from the campaign, never from -j)
  int max_runs = 100;     // per cell
  std::vector<SearchEntryRange> entries;  // one per fault entry
  // The runs made so far, in case order (written by `armfault boundary` into its output's
  // campaign.json). With it the campaign's cases are exactly these runs (CaseAt), not the grid.
  bool has_runs = false;
  std::vector<SearchRun> runs;
};

// Bounds a campaign must meet; each is optional, rates in [0, 1].
struct FloorSet {
  std::optional<double> detection_rate;      // minimum
  std::optional<double> false_alarm_rate;    // maximum
  std::optional<double> isolation_accuracy;  // minimum
};

// Per-family floors are measured on that family's faulty runs; their false_alarm_rate is the
// family's alarm_before_onset_rate (its runs have no healthy part).
struct Floors {
  FloorSet overall;
  std::map<std::string, FloorSet> per_family;  // key: fault family name
  // The monitor's mean time per tick [us] at most (campaigns/running/monitor_cost.h): checked by `run`
  // from monitor_cost.jsonl, outside summary.json (a measurement, not a result).
  std::optional<double> monitor_us_per_tick;
};

struct CampaignSpec {
  std::string source;  // file name, for messages
  std::string base_dir;
  std::string name;
  unsigned long long seed = 1;
  RobotConfig robot;
  double duration_s = 10;
  std::vector<CampaignTrajectory> trajectories;
  std::vector<FaultEntry> faults;
  int healthy = 0;
  int repetitions = 1;
  Variation variation;
  // One healthy commissioning run per unit teaches the monitor that unit (docs/monitor.md);
  // default: on when the campaign states tolerances.
  bool commissioning = false;
  // "commissioning": {"trajectory": NAME, "duration_s": D}: each unit is commissioned on that
  // trajectory of the campaign (its index in `trajectories`) for D seconds, the work it does,
  // instead of the sine motion (campaigns/running/run_pipeline.cc, CommissioningMotion). -1: the sine.
  int commissioning_trajectory = -1;
  double commissioning_duration_s = 0;
  // Score runs whose fault could not act (RunRecord::not_excited_reason) like any other; by
  // default they are listed apart and left out of every rate.
  bool include_not_excited = false;
  // "monitor": its type and settings (the model is built for running: Campaign::monitor_model).
  MonitorSpec monitor;
  Floors floors;
  SearchSpec search;
  nlohmann::json resolved;  // the campaign with defaults filled in (written to campaign.json)
};

// The trajectories' joints, loaded (per trajectory, in order: joint -> trajectory).
using LoadedTrajectories = std::vector<std::map<int, std::shared_ptr<const Trajectory>>>;

// Parses and validates a campaign; every error names the file, the JSON pointer and the value.
// `loaded` null: the trajectories' joints are kept as given, unread (no CSV file is opened).
// Else each trajectory is also loaded into it (checked against the robot over the duration)
// and its errors are reported with the others, as the runner's CampaignFromJson needs.
CampaignSpec CampaignSpecFromJson(const nlohmann::json& value, const std::string& source, const std::string& base_dir,
                                  LoadedTrajectories* loaded = nullptr);

// The number of cases (campaigns/spec/cases.h), without expanding.
long CaseCount(const CampaignSpec& campaign);
// The false alarms per healthy hour the campaign's monitor states it was set for: the power
// monitor's target with "decision": "sequential" (docs/monitor.md); 0 when it states none.
double StatedFalseAlarmsPerHour(const CampaignSpec& campaign);

// A magnitude on the entry's lattice (the search's magnitudes are multiples of it).
double SearchLatticeValue(const SearchEntryRange& range, double magnitude);

}  // namespace armfault
