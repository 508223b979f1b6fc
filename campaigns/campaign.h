// A campaign file: faults swept over magnitudes, onsets, joints and trajectories, healthy
// runs for false-alarm rates, run-to-run variation, the monitor's thresholds and the floors.
// Every key is in docs/campaign-format.md; campaigns/campaign.schema.json is its JSON Schema.
//
// Cases are the product trajectory x fault entry x its swept values x joint x repetition,
// then `healthy` fault-free runs per trajectory. Each case has a stable run_id and a seed
// derived from the campaign seed and that run_id, so a case runs the same on any machine,
// thread or shard.
#pragma once

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/base/json_input.h"
#include "core/monitors/registry.h"
#include "core/plant/robot_config.h"
#include "core/plant/trajectory.h"
#include "campaigns/campaign_summary.h"

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

struct CampaignTrajectory {
  std::string name;
  nlohmann::json joints;  // as given (the run file's "joints" object)
  std::map<int, std::shared_ptr<const Trajectory>> parsed;
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
  int units = 0;           // a fleet of this many robot units; 0: every run is its own unit
};

// One run of a boundary search (`armfault boundary`, campaigns/boundary.h): fault entry
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

struct Campaign {
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
  // Score runs whose fault could not act (RunRecord::not_excited_reason) like any other; by
  // default they are listed apart and left out of every rate.
  bool include_not_excited = false;
  // "monitor": its type and settings, and the model built once from them and the nominal
  // robot (what the monitor knows), shared read-only by every run. A caller may put another
  // model in its place (the Python package does, for a monitor written in Python).
  MonitorSpec monitor;
  std::shared_ptr<const MonitorModel> monitor_model;
  Floors floors;
  SearchSpec search;
  nlohmann::json resolved;  // the campaign with defaults filled in (written to campaign.json)
};

// Parses and validates a campaign; every error names the file, the JSON pointer and the value.
Campaign CampaignFromJson(const nlohmann::json& value, const std::string& source, const std::string& base_dir);
Campaign ReadCampaignFile(const std::string& path);
// The built-in quick thesis sweep (`armfault run` without a file).
Campaign DefaultCampaign();

// One run of a campaign, fully determined.
struct CaseSpec {
  long index = 0;
  std::string run_id;
  size_t trajectory = 0;       // index into Campaign::trajectories
  nlohmann::json fault;        // concrete fault JSON (uniform values drawn); null: healthy
  std::string group;           // family x parameters x joint ("" for healthy)
  unsigned long long seed = 0;
  int repetition = 0;
  // drawn variation
  double extra_payload_kg = 0;
  double torque_noise_Nm = -1;             // < 0: the robot's
  std::vector<double> friction_factors;    // per joint, true friction scale
  int unit = -1;                           // the robot unit (-1: this run is its own unit)
  double ambient_C = 20;
  std::vector<std::vector<double>> tolerance_draws;  // [joint][ToleranceKeys() order]; empty: none
  nlohmann::json VariationJson() const;
};

// The robot of a case's unit: the campaign's robot with the unit's tolerances and friction
// (no run-to-run payload or noise).
RobotConfig UnitRobot(const Campaign& campaign, const CaseSpec& spec);
// The case's robot: its unit's, with the run's payload and sensor noise.
RobotConfig CaseRobot(const Campaign& campaign, const CaseSpec& spec);
// The stated tolerances the monitor may know (with the friction spread and ambient range).
StatedTolerances StatedOf(const Campaign& campaign);

// Case `index` (0 <= index < CaseCount) from the campaign and the index alone: its mixed-radix
// position in trajectory x (fault entry: values x joint x repetition, then healthy runs).
// Nothing is held per case, so counting, shard selection, resume and merge stay flat in
// memory whatever the campaign's size. Throws std::out_of_range outside [0, CaseCount).
CaseSpec CaseAt(const Campaign& campaign, long index);
// All cases in order (CaseAt of every index): for small campaigns and tests.
std::vector<CaseSpec> ExpandCases(const Campaign& campaign);
// The number of cases, without expanding.
long CaseCount(const Campaign& campaign);

// The run_id of a search run: "<trajectory>/<family>#<entry>/<key>=<magnitude>/j<joint>/s<number>".
std::string SearchRunId(const Campaign& campaign, const SearchRun& run);
// A magnitude on the entry's lattice (the search's magnitudes are multiples of it).
double SearchLatticeValue(const SearchEntryRange& range, double magnitude);

// What `validate` (and `run`) warn about in a valid campaign, one line each, naming the JSON
// pointer: a fault entry that targets a joint one of the trajectories leaves still (its runs
// there will be not excited when the family shows only in motion).
std::vector<std::string> CampaignWarnings(const Campaign& campaign);

}  // namespace armfault
