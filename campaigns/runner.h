// Runs a campaign's cases in parallel (oneTBB) and streams one RunRecord per line to
// DIR/results.jsonl in case order, so the file is the same for any thread count and a
// killed run resumes from its last complete line. Files in DIR:
//   campaign.json    the resolved campaign (+ version and shard), written first
//   decisions.jsonl  each run's decision statistics (DecisionLine), one line per run in the
//                    same order, written just before the run's results.jsonl line
//   results.jsonl    one line per run, appended in case order as runs finish
// The summary and junit.xml are written by the caller from results.jsonl (reports/).
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "campaigns/campaign.h"
#include "campaigns/early_stop.h"
#include "campaigns/run_record.h"
#include "core/plant/simulation.h"

namespace armfault {

struct ShardSpec {
  int index = 0;  // 0-based
  int count = 1;
  bool Contains(long case_index) const { return case_index % count == index; }
  // The shard's cases of a campaign of `total`: how many, and the k-th (k from 0) by index.
  long Size(long total) const { return total > index ? (total - index + count - 1) / count : 0; }
  long CaseIndex(long k) const { return index + k * count; }
};

struct RunnerOptions {
  std::string output_dir = "out";
  int threads = 0;  // 0: all cores
  ShardSpec shard;
  bool resume = false;
  // Called after each run is written, with runs done (including resumed ones) and the total.
  std::function<void(long done, long total)> progress;
  // Set (from a signal handler, say) to stop: no run starts after it, the runs in flight
  // finish and are written, and the result says `interrupted`. May be null.
  const std::atomic<bool>* stop = nullptr;
  // Stop as soon as every floor is decided (campaigns/early_stop.h); not with a shard.
  std::optional<EarlyStopOptions> early_stop;
};

struct RunnerResult {
  long total = 0;    // cases in this shard
  long resumed = 0;  // found complete in results.jsonl and decisions.jsonl and not run again
  long ran = 0;
  long failed = 0;   // in the whole results file
  bool interrupted = false;  // stopped before every case ran (RunnerOptions::stop)
  nlohmann::json early_stop;  // --early-stop: what early_stop.json holds (null otherwise)
};
// The lines `run` prints about an early stop: the runs saved and each floor's decision.
std::string EarlyStopSummaryLine(const nlohmann::json& early_stop_json);

RunnerResult RunCampaign(const Campaign& campaign, const RunnerOptions& options);

// The monitor a unit's runs use: the campaign's (the datasheet, widened where tolerances are
// stated) or, with commissioning, that model fitted on the unit's commissioning run.
struct UnitMonitor {
  std::shared_ptr<const MonitorModel> model;
  std::string failure;  // non-empty: the unit's commissioning run failed, and why
};

// The commissioning motion of a robot: every joint on a sine pair of its own frequency, both
// ways through a good part of its range, for 16 s (docs/campaign-format.md, "Commissioning").
nlohmann::json CommissioningMotion(const RobotConfig& robot);
// Commissions the unit of `spec` (its robot, healthy, at the campaign's middle ambient, with a
// seed of the unit's own) and fits the monitor on what it recorded.
UnitMonitor CommissionUnit(const Campaign& campaign, const CaseSpec& spec);

// Per-unit monitors, each computed once, by the first run of that unit that needs it, from any
// thread. Runs that are their own unit are not cached.
class UnitMonitors {
 public:
  explicit UnitMonitors(const Campaign& campaign);
  UnitMonitor For(const CaseSpec& spec);

 private:
  const Campaign& campaign_;
  std::unique_ptr<std::once_flag[]> once_;
  std::vector<UnitMonitor> units_;
};

// Sets a record's diagnosis (detection, latency, isolation, size) from its score.
// A compound run's per-element isolation (RunRecord::compound): each element's "isolated"
// and "detection_time_s" from the first alarm verdict naming its family on its joint at or
// after its onset_s. Nothing for another run.
void ScoreCompoundElements(const MonitorOutput& output, RunRecord* r);
void ApplyScore(const RunScore& score, RunRecord* record);

// One case, fully: builds the varied robot, the faults and the monitor, simulates, diagnoses.
// Never throws for a failing run: the record says "failed" with the reason. `units` (may be
// null) shares the commissioned monitors between the runs of one unit.
RunRecord RunCase(const Campaign& campaign, const CaseSpec& spec, const TickObserver& also = nullptr,
                  UnitMonitors* units = nullptr);

// The JSON written to campaign.json (the summary embeds `resolved` only, so shards merge to
// the same bytes).
nlohmann::json CampaignFileJson(const CampaignSpec& campaign, const ShardSpec& shard);

// One writer per output directory: holds an exclusive lock (flock) on DIR/.armfault.lock, which
// names the holder (pid, host, command, start time). A second writer gets an InputError naming
// that holder. The lock goes with the process, even when it is killed.
class OutputLock {
 public:
  OutputLock(const std::filesystem::path& dir, const std::string& command);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

 private:
  int fd_ = -1;
};

// Writes `text` to `path` through a temporary file and a rename: a crash leaves the old file
// or the new one, never half of one. Throws InputError if it cannot write.
void WriteAtomically(const std::filesystem::path& path, const std::string& text);

}  // namespace armfault
