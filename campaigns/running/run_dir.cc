#include "campaigns/running/run_dir.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <ctime>
#include <fstream>

#include "campaigns/running/monitor_cost.h"
#include "campaigns/running/results_csv.h"
#include "core/base/json_input.h"
#include "core/base/output_file.h"

namespace armfault {

namespace fs = std::filesystem;

const std::vector<RunDirFile>& RunDirFiles() {
  static const std::vector<RunDirFile> files = {
      {run_dir::kCampaign, true},           {run_dir::kResults, true},
      {run_dir::kDecisions, false},         {run_dir::kResultsCsv, false},
      {run_dir::kSummary, true},            {run_dir::kJunit, true},
      {run_dir::kMonitorCost, false},       {run_dir::kMonitorCostSummary, true},
      {run_dir::kEarlyStop, true},          {run_dir::kAlarmsPerHour, true},
  };
  return files;
}

void RemoveNotKeptBySummaryOnly(const fs::path& dir) {
  std::error_code ec;
  for (const RunDirFile& f : RunDirFiles()) {
    if (f.kept_by_summary_only) continue;
    if (!fs::remove(dir / f.name, ec) && ec) throw InputError((dir / f.name).string(), "", "cannot remove: " + ec.message());
  }
}

void ReadRunRecords(const fs::path& path, const JsonLinesOptions& options,
                    const std::function<void(RunRecord&& record, long line)>& each) {
  ReadJsonLines(path.string(), options, [&](nlohmann::json&& line, long n) { each(RunRecordFromJson(line), n); });
}

std::vector<RunRecord> CompleteRunRecords(const fs::path& path) {
  std::vector<RunRecord> out;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  while (std::getline(in, line)) {
    if (in.eof()) break;  // no newline: cut by a kill
    try {
      out.push_back(RunRecordFromJson(nlohmann::json::parse(line)));
    } catch (const std::exception&) {
      break;
    }
  }
  return out;
}

namespace {

// results.csv streams beside the summary (one row at a time: flat in campaign size), into a
// temporary file renamed at the end, so a crash never leaves half of one.
class ResultsCsvOutput : public RecordOutput {
 public:
  explicit ResultsCsvOutput(const fs::path& dir) : csv_(dir / run_dir::kResultsCsv) { csv_.Write(ResultsCsvHeader()); }
  void Add(const RunRecord& record) override { csv_.Write(ResultsCsvRow(record)); }
  void Finish(const SummaryBuilder&) override { csv_.Commit(); }

 private:
  AtomicOutputFile csv_;  // not finished (an error): no half file left behind
};

// summary.json, with an early-stopped run's decisions (early_stop.json) and a replay's alarms per
// hour (alarms_per_hour.json) beside the rates; without the latter, the healthy runs' false
// alarms per hour of the campaign's duration (healthy_operation).
class SummaryJsonOutput : public RecordOutput {
 public:
  SummaryJsonOutput(const fs::path& dir, const CampaignSpec& campaign) : dir_(dir), campaign_(campaign) {}
  void Finish(const SummaryBuilder& all) override {
    nlohmann::json summary = all.Build(campaign_.floors, campaign_.resolved, ARMFAULT_VERSION);
    if (const fs::path early_path = dir_ / run_dir::kEarlyStop; fs::exists(early_path)) {
      summary["early_stop"] = ReadJsonFile(early_path.string());
    }
    // `replay`: the false alarms per hour of operation of its healthy and unlabelled runs.
    if (const fs::path alarms_path = dir_ / run_dir::kAlarmsPerHour; fs::exists(alarms_path)) {
      summary["alarms_per_hour"] = ReadJsonFile(alarms_path.string());
    } else {
      summary["healthy_operation"] = HealthyOperationOf(all, campaign_.duration_s, StatedFalseAlarmsPerHour(campaign_)).ToJson();
    }
    WriteAtomically(dir_ / run_dir::kSummary, summary.dump(2) + "\n");
  }

 private:
  fs::path dir_;
  const CampaignSpec& campaign_;
};

class JunitXmlOutput : public RecordOutput {
 public:
  JunitXmlOutput(const fs::path& dir, const CampaignSpec& campaign) : dir_(dir), campaign_(campaign) {}
  void Finish(const SummaryBuilder& all) override {
    WriteAtomically(dir_ / run_dir::kJunit, JUnitXml(campaign_.name, all, campaign_.floors, run_dir::kCampaign));
  }

 private:
  fs::path dir_;
  const CampaignSpec& campaign_;
};

// monitor_cost.json from the directory's monitor_cost.jsonl (campaigns/running/monitor_cost.h).
class MonitorCostOutput : public RecordOutput {
 public:
  MonitorCostOutput(const fs::path& dir, const CampaignSpec& campaign, std::optional<double> heap_bytes)
      : dir_(dir), campaign_(campaign), heap_bytes_(heap_bytes) {}
  void Finish(const SummaryBuilder&) override {
    const nlohmann::json cost = SummarizeMonitorCost(dir_ / run_dir::kMonitorCost, heap_bytes_,
                                                     campaign_.floors.monitor_us_per_tick, campaign_.monitor.type);
    WriteAtomically(dir_ / run_dir::kMonitorCostSummary, cost.dump(2) + "\n");
  }

 private:
  fs::path dir_;
  const CampaignSpec& campaign_;
  std::optional<double> heap_bytes_;
};

}  // namespace

const std::vector<RecordOutputRow>& RecordOutputs() {
  using Options = RecordOutputOptions;
  static const std::vector<RecordOutputRow> rows = {
      {run_dir::kResultsCsv,
       [](const fs::path& dir, const CampaignSpec&, const Options&) -> std::unique_ptr<RecordOutput> {
         return std::make_unique<ResultsCsvOutput>(dir);
       }},
      {run_dir::kSummary,
       [](const fs::path& dir, const CampaignSpec& c, const Options&) -> std::unique_ptr<RecordOutput> {
         return std::make_unique<SummaryJsonOutput>(dir, c);
       }},
      {run_dir::kJunit,
       [](const fs::path& dir, const CampaignSpec& c, const Options&) -> std::unique_ptr<RecordOutput> {
         return std::make_unique<JunitXmlOutput>(dir, c);
       }},
      {run_dir::kMonitorCostSummary,
       [](const fs::path& dir, const CampaignSpec& c, const Options& o) -> std::unique_ptr<RecordOutput> {
         if (!o.monitor_cost.write) return nullptr;
         return std::make_unique<MonitorCostOutput>(dir, c, o.monitor_cost.heap_bytes);
       }},
  };
  return rows;
}

RecordOutputsResult WriteRecordOutputs(const fs::path& dir, const CampaignSpec& campaign, bool summary_only,
                                       const RecordOutputOptions& output_options) {
  RecordOutputsResult out{SummaryBuilder(campaign.include_not_excited), {}, {}, std::nullopt};
  std::vector<std::unique_ptr<RecordOutput>> outputs;
  for (const RecordOutputRow& row : RecordOutputs()) {
    bool kept = true;
    for (const RunDirFile& f : RunDirFiles()) {
      if (std::string(f.name) == row.file) kept = f.kept_by_summary_only;
    }
    if (summary_only && !kept) continue;
    if (std::unique_ptr<RecordOutput> output = row.make(dir, campaign, output_options)) outputs.push_back(std::move(output));
  }
  long previous_case = -1;
  JsonLinesOptions options;
  options.open_error = "cannot read the file";
  ReadRunRecords(dir / run_dir::kResults, options, [&](RunRecord&& record, long) {
    if (record.case_index <= previous_case) {
      throw std::runtime_error("case " + std::to_string(record.case_index) + " (run \"" + record.run_id +
                               "\") comes after case " + std::to_string(previous_case) +
                               ": a run appears twice or out of order (did two commands write into this "
                               "directory?); run the campaign again into an empty directory");
    }
    previous_case = record.case_index;
    out.summary.Add(record);
    for (const auto& o : outputs) o->Add(record);
  });
  for (const auto& o : outputs) o->Finish(out.summary);
  out.verdicts = out.summary.Verdicts(campaign.floors);
  if (output_options.monitor_cost.write) out.monitor_cost = ReadJsonFile((dir / run_dir::kMonitorCostSummary).string());
  if (const fs::path early_path = dir / run_dir::kEarlyStop; fs::exists(early_path)) {
    const nlohmann::json early_stop = ReadJsonFile(early_path.string());
    for (const nlohmann::json& f : early_stop.at("floors")) {
      if (f["decided"].get<bool>()) out.early_stop_decided[f["name"].get<std::string>()] = f["met"].get<bool>();
    }
  }
  return out;
}

nlohmann::json ReadCampaignFileJson(const fs::path& dir) {
  const fs::path path = dir / run_dir::kCampaign;
  nlohmann::json file = ReadJsonFile(path.string());
  if (!file.is_object() || !file.contains("campaign") || !file["campaign"].is_object()) {
    throw InputError(path.string(), "/campaign", "missing: not the campaign.json of an armfault output directory");
  }
  return file;
}

CampaignSpec ReadRunDirCampaign(const fs::path& dir) {
  return CampaignSpecFromJson(ReadCampaignFileJson(dir)["campaign"], (dir / run_dir::kCampaign).string(), dir.string());
}

nlohmann::json CampaignFileJson(const CampaignSpec& campaign, const ShardSpec& shard) {
  return {{"armfault_version", ARMFAULT_VERSION},
          {"shard", {{"index", shard.index}, {"count", shard.count}}},
          {"cases", CaseCount(campaign)},
          {"campaign", campaign.resolved}};
}

OutputLock::OutputLock(const fs::path& dir, const std::string& command) {
  std::error_code ec;
  if (fs::is_symlink(fs::symlink_status(dir, ec))) {
    throw InputError(dir.string(), "",
                     "the output directory is a symbolic link; armfault does not write through links: give the "
                     "directory itself");
  }
  fs::create_directories(dir);
  path_ = (dir / run_dir::kLock).string();
  // The holder removes the file as it lets go, so the file this process opened may be unlinked
  // between its open and its flock: then the lock is on a file no one else will open, and it
  // tries again on the one at the path.
  for (int attempt = 0;; ++attempt) {
    fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd_ < 0) throw InputError(path_, "", "cannot open the directory's lock file");
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      std::string holder(512, '\0');
      const ssize_t n = ::pread(fd_, holder.data(), holder.size(), 0);
      holder.resize(n > 0 ? static_cast<size_t>(n) : 0);
      while (!holder.empty() && (holder.back() == '\n' || holder.back() == '\0')) holder.pop_back();
      ::close(fd_);
      fd_ = -1;
      throw InputError(dir.string(), "",
                       "another armfault is writing here (" + (holder.empty() ? std::string("holder unknown") : holder) +
                           "); wait for it to finish, or choose another output directory");
    }
    struct stat held {}, at_path {};
    if (::fstat(fd_, &held) == 0 && ::lstat(path_.c_str(), &at_path) == 0 && held.st_dev == at_path.st_dev &&
        held.st_ino == at_path.st_ino) {
      break;
    }
    ::close(fd_);
    fd_ = -1;
    if (attempt >= 100) throw InputError(path_, "", "the directory's lock file keeps being replaced");
  }
  char host[256] = "?";
  gethostname(host, sizeof host - 1);
  const std::time_t now = std::time(nullptr);
  char when[32];
  std::strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  const std::string text = "pid " + std::to_string(getpid()) + " on " + host + " since " + when + ": " + command + "\n";
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, text.data(), text.size(), 0) < 0) {
    // The lock holds; only the holder's description could not be written.
  }
}

OutputLock::~OutputLock() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());  // before letting go: the next writer's file is a new one
  ::close(fd_);             // releases the flock
}

void RequireNoOtherResults(const fs::path& dir, const nlohmann::json& campaign_file, bool force) {
  if (force) return;
  const fs::path campaign_path = dir / run_dir::kCampaign, results_path = dir / run_dir::kResults;
  // A link in place of results.jsonl is not results: the writer refuses it (never through a link).
  std::error_code ec;
  const bool has_results =
      fs::is_regular_file(fs::symlink_status(results_path, ec)) && fs::file_size(results_path, ec) > 0 && !ec;
  if (!fs::exists(campaign_path) && !has_results) return;
  std::string held = "results.jsonl without its campaign.json";
  if (fs::exists(campaign_path)) {
    nlohmann::json existing;
    try {
      existing = ReadJsonFile(campaign_path.string());
    } catch (const std::exception&) {
      existing = nullptr;
    }
    const nlohmann::json* c = existing.is_object() ? &existing : nullptr;
    if (c && c->value("campaign", nlohmann::json()) == campaign_file.value("campaign", nlohmann::json()) &&
        c->value("shard", nlohmann::json()) == campaign_file.value("shard", nlohmann::json())) {
      return;  // this campaign and shard again: a rerun
    }
    held = "a campaign.json that is not armfault's";
    if (c && c->contains("campaign") && (*c)["campaign"].is_object()) {
      const nlohmann::json& other = (*c)["campaign"];
      const std::string name = other.contains("name") && other["name"].is_string() ? other["name"].get<std::string>() : "";
      held = (name.empty() ? std::string("another campaign's results") : "the results of campaign \"" + name + "\"") +
             (other == campaign_file.value("campaign", nlohmann::json()) ? " (another shard)" : "");
    }
  }
  throw InputError(dir.string(), "",
                   "holds " + held + "; they are kept: --resume continues only the same campaign and shard, --force "
                   "replaces them, or choose another output directory");
}


}  // namespace armfault
