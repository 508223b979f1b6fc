// `armfault replay DIR`: any monitor run over recorded signals (an export's, or an import's: the
// same layout, campaigns/data/export.h) tick by tick, and its verdicts scored as a live run's are.
//
// DIR holds campaign.json (the robot, the monitor, the floors), manifest.jsonl (one run a line:
// run_id, signals file, and the truth when known) and runs/*.csv.gz (t_s, then every joint's
// JointSignals, SignalsCsvHeader). Each run's signals are fed to a fresh monitor of the chosen
// model exactly as the plant's loop feeds it (Observe at every tick, Finish at the last), with
// scoring's decision tap beside it, and the record is made by the run pipeline's ScoreRun: so a
// replayed export gives the campaign's `armfault run` results.jsonl line for line (the onset
// read back from the manifest is the recorded one: see docs/monitor-api.md, "Replay").
//
// A manifest row's label: a fault family (scored as a live run's); "family" null, "" or "healthy" (a
// healthy run, as export writes one); no "family" key at all, or "label": "unknown" or
// "unlabelled" (a log nobody labelled): scored for false alarms only, as a healthy run, and its
// record says "label": "unlabelled". Healthy and unlabelled runs give the alarms per hour of
// operation (AlarmRate).
#pragma once

#include <nlohmann/json.hpp>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "campaigns/spec/campaign.h"
#include "campaigns/scoring/provenance.h"
#include "core/plant/robot/robot_config.h"
#include "core/signals/joint_signals.h"

namespace armfault {

// Streams one run's signals file (gzip CSV as export writes it: header SignalsCsvHeader(joints),
// then one row a tick, empty cell = NaN) to `each`, tick by tick, never holding the run. Errors
// name the file and its line: a header that is not the expected one (names the first column
// that differs), a row with another number of cells, a cell that is not a number, time not
// increasing. Returns the number of ticks.
long ReadSignalsCsv(const std::string& path, int joints,
                    const std::function<void(double t_s, const std::vector<JointSignals>& joints)>& each);

// One run's signals, read whole (ReadSignalsCsv) into `ticks` (and their times into `t_s`),
// for a command that reads a log at the robot's control rate (calibrate, report --twin):
// InputError naming the file and the two ticks that are not one control period apart.
void ReadSignalsAtControlRate(const std::string& path, int joints, double control_dt_s,
                              std::vector<std::vector<JointSignals>>* ticks, std::vector<double>* t_s);

// DIR/manifest.jsonl's line of `run` (an export's or an import's): InputError without the
// file, for a line without a string "run_id", and from `option` ("--run") for an unknown run,
// naming the nearest run_id.
nlohmann::json ManifestLine(const std::string& dir, const std::string& run, const std::string& option);
// DIR/manifest.jsonl's lines in order (InputError as ManifestLine's).
std::vector<nlohmann::json> ManifestLines(const std::string& dir);

// The robot DIR's runs were recorded with: DIR/campaign.json's /campaign/robot, as run,
// export and import write it. InputError naming the file (and `hint`, what to do instead,
// when it or the key is missing).
RobotConfig RecordedRobot(const std::string& dir, const std::string& hint);

// The false alarms of healthy and unlabelled runs per hour of operation. An alarm is counted at
// its onset: a verdict with alarm true whose joint's previous verdict was not an alarm (a joint
// alarming for an hour is one alarm, two joints alarming at once two). Hours: each run's last
// tick time less its first. Bound: the one-sided 95 % upper bound of a Poisson count
// (PoissonUpperBound) over the same hours.
struct AlarmRate {
  long healthy_runs = 0;
  long unlabelled_runs = 0;
  long alarm_onsets = 0;
  double hours = 0;
  std::string excluded_run;  // the --commission run, left out (the monitor learned on it)
  // {"healthy_runs", "unlabelled_runs", "hours", "alarm_onsets", "per_hour", "per_hour_upper_95",
  //  "counted", ["excluded_run"]}; per_hour and the bound null when there are no hours.
  nlohmann::json ToJson() const;
};

// OUT/replay.json, which `replay` writes beside its results: where the signals came from, so
// that what reads OUT later (report, tune, report --twin) knows it holds recorded runs.
//   {"source": DIR as given, "source_absolute": DIR made absolute, "import": DIR has import.json}
inline constexpr const char* kReplayFile = "replay.json";
struct ReplaySource {
  std::string file;  // OUT/replay.json, for messages
  std::string dir;   // the source directory as found: source_absolute, else source as given
  bool import = false;
};
// OUT/replay.json's source; nullopt when OUT has no replay.json (a run's output, for one).
// InputError naming the file and the JSON pointer: a field of the wrong type, or a source
// directory that is found neither as source_absolute nor as source (the data moved).
std::optional<ReplaySource> ReadReplaySource(const std::string& out_dir);
// When OUT is a replay of an import: the import's manifest runs (case, run_id), which its
// records are checked against instead of the stand-in campaign's cases; else nullopt.
// InputError as ReadReplaySource's and ManifestLines'.
std::optional<RecordedRuns> ReplayedImportRuns(const std::string& out_dir);

struct ReplayOptions {
  std::string dir;                // an export or an import
  std::string output_dir;         // default: DIR/replayed
  std::string monitor_file;       // a JSON object as a campaign's "monitor" key; empty: the campaign's
  std::string commission_run;     // a run_id of DIR: the built-in commissioning from its signals
  int threads = 0;                // 0: all cores; never changes a result
  std::function<void(long done, long total)> progress;
};
struct ReplayResult {
  long runs = 0;
  long failed = 0;
  Campaign campaign;  // as replayed (its monitor the one run), as campaign.json holds it
  AlarmRate alarms;
};
// Replays every run of DIR's manifest (case order kept; runs in parallel, the same bytes for any
// thread count) and writes OUT/{campaign.json, decisions.jsonl, results.jsonl,
// monitor_cost.jsonl, alarms_per_hour.json, replay.json}; the caller writes the summary, results.csv and
// junit.xml from results.jsonl (FinishRunDirectory, as `run` and `score` do), summary.json
// embedding alarms_per_hour.json. InputErrors (exit 2) name the path: DIR that is not a
// directory, a missing campaign.json or manifest.jsonl, a manifest line, a signals file, M.json
// and its JSON pointer, --commission naming an unknown run (with the nearest) or a faulty one.
ReplayResult ReplayDirectory(const ReplayOptions& options);

}  // namespace armfault
