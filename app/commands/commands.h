// The armfault subcommands. Each returns the process exit status:
// 0 success, 1 a floor missed, 2 invalid input or usage, 3 some runs failed.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "campaigns/thesis/thesis.h"

namespace armfault {

class StatisticsCsvWriter;

struct TraceOptions {
  std::string run_file;                 // empty: thesis experiment 1
  std::string robot;                    // overrides the file's robot (preset name)
  std::optional<double> duration_s;     // overrides the file's duration
  std::optional<long long> seed;        // overrides the file's seed
  std::vector<std::string> joint_specs; // "J=<trajectory JSON>"
  std::vector<std::string> fault_specs; // fault JSON objects, added to the file's "faults"
  std::string output = "trace.csv";
  std::string monitor_output;           // monitor verdicts and windows as JSON (optional)
  // Every published statistic per tick and joint beside its threshold, as CSV (optional;
  // reports/statistics_csv.h).
  std::string statistics_output;
  bool quiet = false;
  // With run_id, run_file is a campaign and TraceCampaignCase re-runs that one case of it
  // exactly as the campaign ran it (RunCase); robot, duration, seed, joints and faults stay unset.
  std::string run_id;                   // a run_id or a case number
};
int RunTrace(const TraceOptions& options);
// "statistics: kt_deficit, ... -> FILE" (or that the monitor publishes none), for --statistics.
void PrintStatistics(const StatisticsCsvWriter& statistics, const std::string& file);
// Writes the case's trace (and --monitor-out), prints its record; 0, 3 if the run failed,
// 2 for an unknown run_id (the message suggests the nearest one).
int TraceCampaignCase(const TraceOptions& options);

struct RobotCommandOptions {
  std::string robot;     // a preset name or a JSON file (a robot, or a run or campaign file)
  std::string urdf_dir;  // empty: print the robot in full; else write NAME.urdf and NAME.robot.json here
};
// A robot named on the command line: a preset name, or a JSON file holding a robot (the robot
// itself, or a run or campaign file: its "robot"); relative paths inside it are relative to the
// file. Throws InputError.
struct RobotConfig;
RobotConfig ReadRobotArgument(const std::string& what);
// Prints the robot with every key filled in, or writes it as a URDF plus a robot file naming it
// and its drives (read back, the same plant). 0, or 2 for bad input.
int RobotCommand(const RobotCommandOptions& options);

struct ThesisOptions {
  std::string output_dir = "out";
  unsigned long long seed = 1;
};
// Runs the thesis experiments, prints them beside the thesis figures, writes thesis.json and
// thesis.md. Exit 0 if the trend holds (table 5-3 monotonic, ratios within 0.10 of the
// thesis, experiments 2 and 3 drop), else 1.
int RunThesis(const ThesisOptions& options);

struct ThesisTrend {
  static constexpr double kRatioLimit = 0.10;
  bool monotonic = true;
  double max_ratio_deviation = 0;
  bool same_direction = true;
  bool holds() const { return monotonic && max_ratio_deviation <= kRatioLimit && same_direction; }
};
ThesisTrend CheckThesisTrend(const ThesisResults& results);

struct CampaignRunOptions {
  std::string campaign_file;   // empty: the built-in thesis sweep
  std::string output_dir = "out";
  int threads = 0;             // 0: all cores
  std::string shard;           // "K/N"; empty: SLURM_ARRAY_TASK_ID/COUNT, JOB_COMPLETION_INDEX, or all
  int shard_count = 0;         // with JOB_COMPLETION_INDEX
  bool resume = false;
  // Replace the results of another campaign in the output directory (without it: exit 2, kept).
  bool force = false;
  bool quiet = false;
  // CI artefacts: once the summary is written, remove decisions.jsonl (only `tune` reads it)
  // and results.csv (a flat copy of results.jsonl); results.jsonl stays for diff and report.
  bool summary_only = false;
  // Stop as soon as every floor is decided at this confidence (campaigns/scoring/early_stop.h).
  bool early_stop = false;
  double early_stop_confidence = 0.99;
};
// Runs a campaign and writes DIR/{campaign.json, results.jsonl, decisions.jsonl, results.csv,
// summary.json, junit.xml}. 0 all floors met, 1 a floor missed, 3 some runs failed.
int RunCampaignCommand(const CampaignRunOptions& options);
// The shard a command runs: --shard K/N, else SLURM_ARRAY_TASK_ID/COUNT, else
// JOB_COMPLETION_INDEX with --shard-count, else the whole campaign. Errors name the option.
struct ShardSpec;
ShardSpec ResolveShard(const CampaignRunOptions& options);

struct ExportOptions;
struct ExportCommandOptions {
  std::string campaign_file;
  std::string output_dir = "export";
  int threads = 0;
  std::string shard;
  int shard_count = 0;
  std::string split;  // "TRAIN/VALIDATION/TEST" fractions; empty: no split
  int gzip_level = 1;  // kDefaultGzipLevel; zlib level of runs/*.csv.gz (ExportOptions::gzip_level)
  bool quiet = false;
};
// Writes DIR/{campaign.json, manifest.jsonl, manifest.csv, runs/*.csv.gz}; 0, or 3 if runs failed.
int ExportCommand(const ExportCommandOptions& options);

struct ImportCommandOptions {
  std::vector<std::string> logs;  // CSV logs (plain or gzip)
  std::string map_file;           // MAP.json (campaigns/data/import.h)
  std::string output_dir;         // must not exist, or be empty
  bool quiet = false;
};
// Writes DIR/{campaign.json, manifest.jsonl, manifest.csv, channels.json, import.json,
// runs/*.csv.gz} as `export` does, or nothing (status 2) when a log or the map is bad.
int ImportCommand(const ImportCommandOptions& options);

struct ScoreCommandOptions {
  std::string dir;            // an export (manifest.jsonl) or run (results.jsonl) output directory
  std::string verdicts_file;  // JSON Lines: run_id, t_s, joint, family, alarm, magnitude
  std::string output_dir;     // default: DIR/scored
};
// Scores the verdicts and writes results.jsonl, results.csv, summary.json, junit.xml as `run`
// does, with the same floors and exit status.
int ScoreCommand(const ScoreCommandOptions& options);

struct ReplayCommandOptions {
  std::string dir;             // an export or an import (manifest.jsonl, runs/*.csv.gz, campaign.json)
  std::string monitor_file;    // a campaign's "monitor" value as a JSON file; empty: the campaign's
  std::string output_dir;      // default: DIR/replayed
  std::string commission_run;  // a healthy run of DIR the monitor commissions from
  int threads = 0;             // 0: all cores
  bool quiet = false;
};
// Replays DIR's signals through the monitor (campaigns/data/replay.h) and writes results.jsonl,
// decisions.jsonl, results.csv, summary.json (with alarms_per_hour), junit.xml as `run` does,
// with the same floors and exit status; prints the alarms per hour of operation.
int ReplayCommand(const ReplayCommandOptions& options);

struct CalibrateCommandOptions {
  std::string dir;          // an export or an import
  std::string run;          // the healthy run_id to calibrate on
  std::string robot;        // the datasheet (preset or file); empty: DIR's campaign.json robot
  std::string output_file;  // the twin's robot file; its .calibration.json beside it
  double block_s = 2.0;
  int resamples = 400;
};
// Fits the unit of RUN (campaigns/data/calibrate.h), prints each value with its 95 % interval and the
// residuals, writes the twin and the estimates (docs/calibration.md).
int CalibrateCommand(const CalibrateCommandOptions& options);

struct ValidateOptions {
  std::string campaign_file;
  bool load_plugins = false;  // build a monitor that runs the user's code (a plugin library)
};
int ValidateCommand(const ValidateOptions& o);

struct MergeOptions {
  std::vector<std::string> input_dirs;  // output directories of `armfault run --shard K/N`
  std::string output_dir;
};
// Joins the shards (campaigns/running/merge.h) and writes summary.json and junit.xml as `run` does:
// 0 all floors met, 1 a floor missed, 3 some runs failed, 2 bad or incomplete shards.
int MergeCommand(const MergeOptions& options);

struct TuneCommandOptions {
  std::string dir;                  // an `armfault run` output directory
  std::string sweep;                // "kt_factor.worn=0.85:0.99:15,..." (campaigns/tuning/tuning.h)
  std::string rule = "max_detection";  // max_detection, youden, min_cost
  double false_alarm_ceiling = 0.01;
  double miss_cost = 1, false_alarm_cost = 1;
  std::string monitor_output;       // tuned monitor JSON; default DIR/tuned-monitor.json
  int threads = 0;
};
// Writes DIR/tuning.json and the tuned monitor; 0, or 2 on bad input.
int TuneCommand(const TuneCommandOptions& options);

// Prints the cost of a run against bare ODE ("ratio: X") and "parallel efficiency: Y": of the
// thesis sweep on mrr-config1, or of healthy 10-s runs of `robot` (a preset or a robot file).
int BenchCommand(int repeats, const std::string& robot = "", const std::string& engine = "");

// `bench --duration S ...` (or `--shift`: 10 s, 10 min, 1 h): for each length S, in a process of
// its own (forked, so each peak is that length's alone), the least CPU time of `repeats` runs
// of one healthy case of mrr-config1 with all three joints moving (the campaign pipeline:
// monitor, tap, effect meters, clock) and the process's peak RSS; then the time and memory
// per simulated second and the marginal time per simulated second between consecutive lengths.
int BenchLengthCommand(const std::vector<double>& durations_s, int repeats);

struct DiffCommandOptions {
  std::string dir_a, dir_b;         // baseline, candidate: armfault run output directories
  double alpha = 0.05;              // significance level
  double tolerance = 0;             // allowed worsening of a rate
  double latency_tolerance_s = 0;   // allowed increase of the median latency [s]
  std::string json_output;          // diff.json (optional)
  std::string markdown_output;      // diff.md (optional)
};
// Compares two campaign results (reports/campaign_diff.h); prints the table. 0 nothing
// significantly worse, 1 something is (each printed as "worse: ..."), 2 bad input.
int DiffCommand(const DiffCommandOptions& options);

struct BoundaryCommandOptions {
  std::string campaign_file;   // a campaign with a "search" block
  std::string from_dir;        // instead: estimate from the runs already in this directory
  std::string output_dir = "out";
  int threads = 0;             // 0: all cores; never changes a result
  bool resume = false;
  int max_batches = 0;         // > 0: stop after this many batches (--resume continues)
  bool quiet = false;
};
// The boundary search (campaigns/tuning/boundary.h): writes DIR/boundary.json beside a run's files
// and prints the table. 0, 2 bad input, 3 some runs failed, 130 interrupted.
int BoundaryCommand(const BoundaryCommandOptions& options);

struct ReportCommandOptions {
  std::string dir;      // an `armfault run` output directory
  std::string run_id;   // the run plotted over time; empty: the first missed faulty run
  std::string output;   // the HTML file; empty: DIR/report.html (the .md goes beside it)
  // --twin: a robot file (as `armfault calibrate` writes one) or preset, run along one recorded
  // run's reference and compared with the recording (campaigns/data/twin_compare.h).
  std::string twin_file;
  std::string twin_run;      // the run compared; empty: the calibration's, else the first healthy
  std::string recorded_dir;  // the export or import replayed; empty: DIR or its parent
};
// Writes the campaign report (reports/page/campaign_report.h): report.html and report.md. 0, or 2
// for bad input.
int ReportCommand(const ReportCommandOptions& options);

}  // namespace armfault
