// The run directory: what `run`, `merge`, `score`, `boundary`, `export` and the Python package
// write into an output directory, and how it is read back. One place for
//   - the file names and which of them `--summary-only` keeps (RunDirFiles);
//   - the one reader of run records (ReadRunRecords, CompleteRunRecords), which names a bad line;
//   - the one table of the outputs written from results.jsonl once the runs are in
//     (results.csv, summary.json, junit.xml: WriteRecordOutputs), the same for every command;
//   - writing safely: one writer per directory (OutputLock), whole files or none
//     (WriteAtomically).
// Files (docs/campaign-format.md, "Output files"):
//   campaign.json       the resolved campaign, version and shard (CampaignFileJson), first
//   decisions.jsonl     each run's decision statistics, one line per run, before its result line
//   results.jsonl       one RunRecord per line, in case order
//   results.csv         results.jsonl as one flat row per run
//   summary.json        rates, intervals, confusion matrix, latency, floors (+ early_stop)
//   junit.xml           the floors as test cases
//   monitor_cost.jsonl  the monitor's cost per run; monitor_cost.json its campaign figures
//   early_stop.json     `run --early-stop`: the floors' decisions
//   alarms_per_hour.json `replay`: false alarms per hour of operation (campaigns/data/replay.h)
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "campaigns/spec/campaign_spec.h"
#include "campaigns/scoring/campaign_summary.h"
#include "campaigns/scoring/run_record.h"
#include "core/base/output_file.h"  // WriteAtomically, AtomicOutputFile

namespace armfault {

// Which cases a shard runs: those with case % count == index. campaign.json records it.
struct ShardSpec {
  int index = 0;  // 0-based
  int count = 1;
  bool Contains(long case_index) const { return case_index % count == index; }
  // The shard's cases of a campaign of `total`: how many, and the k-th (k from 0) by index.
  long Size(long total) const { return total > index ? (total - index + count - 1) / count : 0; }
  long CaseIndex(long k) const { return index + k * count; }
};

namespace run_dir {
inline constexpr const char* kCampaign = "campaign.json";
inline constexpr const char* kResults = "results.jsonl";
inline constexpr const char* kDecisions = "decisions.jsonl";
inline constexpr const char* kResultsCsv = "results.csv";
inline constexpr const char* kSummary = "summary.json";
inline constexpr const char* kJunit = "junit.xml";
inline constexpr const char* kMonitorCost = "monitor_cost.jsonl";
inline constexpr const char* kMonitorCostSummary = "monitor_cost.json";
inline constexpr const char* kEarlyStop = "early_stop.json";
inline constexpr const char* kAlarmsPerHour = "alarms_per_hour.json";
inline constexpr const char* kLock = ".armfault.lock";
}  // namespace run_dir

// One file of a run directory: its name and whether `--summary-only` keeps it (small CI
// artefacts: decisions.jsonl is most of the bytes and only `tune` reads it; results.csv repeats
// results.jsonl, which diff and report need; monitor_cost.jsonl is per run).
struct RunDirFile {
  const char* name;
  bool kept_by_summary_only;
};
const std::vector<RunDirFile>& RunDirFiles();
// --summary-only: removes the files it does not keep (a stale one from an earlier run too).
void RemoveNotKeptBySummaryOnly(const std::filesystem::path& dir);

// Every record of a results.jsonl (or any JSON Lines of records) with its line number, in
// order; a line that is not a record, or that `each` refuses by throwing, is an InputError
// "PATH: line N: why" (core/base/json_input.h, ReadJsonLines).
void ReadRunRecords(const std::filesystem::path& path, const JsonLinesOptions& options,
                    const std::function<void(RunRecord&& record, long line)>& each);
// The complete lines at the start of results.jsonl that are records, in order: what a killed
// writer left (its last line may be cut). A missing file has none.
std::vector<RunRecord> CompleteRunRecords(const std::filesystem::path& path);

// An output written from the run records once the runs are in: fed every record in case order,
// then finished with the summary of them all. One row of RecordOutputs() per file.
class RecordOutput {
 public:
  virtual ~RecordOutput() = default;
  virtual void Add(const RunRecord& record) { (void)record; }
  virtual void Finish(const SummaryBuilder& all) = 0;
};
// monitor_cost.json, a measurement of this machine (campaigns/running/monitor_cost.h): made from
// DIR/monitor_cost.jsonl when `write`, with `heap_bytes` the heap one monitor held (`run`'s probe,
// the largest of `merge`'s shards; nullopt: not measured).
struct MonitorCostInput {
  bool write = false;
  std::optional<double> heap_bytes;
};
// What a command gives the table beyond the directory and its campaign.
struct RecordOutputOptions {
  MonitorCostInput monitor_cost;
};
struct RecordOutputRow {
  const char* file;  // a RunDirFiles() name: --summary-only writes the rows it keeps
  // The row's writer; nullptr when the command writes no such file (monitor_cost.json unasked).
  std::unique_ptr<RecordOutput> (*make)(const std::filesystem::path& dir, const CampaignSpec& campaign,
                                        const RecordOutputOptions& options);
};
const std::vector<RecordOutputRow>& RecordOutputs();

// What WriteRecordOutputs read: the summary of every record, the floors' verdicts and, for an
// early-stopped run, each decided floor's decision (its name: met), which the exit status follows;
// and monitor_cost.json's content when it was written.
struct RecordOutputsResult {
  SummaryBuilder summary;
  std::vector<FloorVerdict> verdicts;
  std::map<std::string, bool> early_stop_decided;
  std::optional<nlohmann::json> monitor_cost;
};
// Reads DIR/results.jsonl once and writes every row of RecordOutputs() (only those
// --summary-only keeps when `summary_only`). The runner and merge write each case once, in case
// order: a case again, or out of order, is an InputError naming the line (two writers shared the
// directory; counting it twice would lie).
RecordOutputsResult WriteRecordOutputs(const std::filesystem::path& dir, const CampaignSpec& campaign, bool summary_only,
                                       const RecordOutputOptions& options = {});

// DIR/campaign.json as armfault wrote it (CampaignFileJson), checked to hold a "campaign"
// object: the one reader of it for every command that reads a run directory.
nlohmann::json ReadCampaignFileJson(const std::filesystem::path& dir);
// The campaign of DIR/campaign.json (relative file names resolve against DIR).
CampaignSpec ReadRunDirCampaign(const std::filesystem::path& dir);

// The JSON written to campaign.json (the summary embeds `resolved` only, so shards merge to
// the same bytes).
nlohmann::json CampaignFileJson(const CampaignSpec& campaign, const ShardSpec& shard);

// One writer per output directory: holds an exclusive lock (flock) on DIR/.armfault.lock, which
// names the holder (pid, host, command, start time). A second writer gets an InputError naming
// that holder. An output directory that is a symbolic link is refused (InputError): armfault
// never writes through a link. The lock file is removed when the lock is let go (every exit
// through a destructor; ExitGate::RemoveOnExit for an exit at once); the flock itself goes with
// the process, even when it is killed, so a file a kill -9 left behind locks nothing.
class OutputLock {
 public:
  OutputLock(const std::filesystem::path& dir, const std::string& command);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;
  // The lock file's path (for ExitGate::RemoveOnExit); alive as long as the lock.
  const char* path() const { return path_.c_str(); }

 private:
  int fd_ = -1;
  std::string path_;
};

// `run` without --resume: a directory that holds another campaign's (or shard's) results is kept
// and refused (InputError naming the directory and the campaign there), unless `force`. The same
// campaign and shard run again, or a directory without results, pass.
void RequireNoOtherResults(const std::filesystem::path& dir, const nlohmann::json& campaign_file, bool force);

}  // namespace armfault
