#include "campaigns/running/runner.h"

#include <stdio_ext.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <system_error>

#include "campaigns/running/ordered_pipeline.h"
#include "campaigns/scoring/early_stop.h"
#include "core/base/output_file.h"

namespace armfault {

namespace {

namespace fs = std::filesystem;

// The complete lines at the start of `path` (at most `limit`) that `accept` takes, as the byte
// offset after each. Stops at the first line it refuses and at a last line without a newline
// (cut by a kill). A missing file has none.
std::vector<std::streamoff> AcceptedLineEnds(const fs::path& path, size_t limit,
                                             const std::function<bool(size_t k, const std::string& line)>& accept) {
  std::vector<std::streamoff> ends;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  while (ends.size() < limit && std::getline(in, line)) {
    if (in.eof()) break;  // no newline: a line cut by a crash
    if (!accept(ends.size(), line)) break;
    ends.push_back(in.tellg());
  }
  return ends;
}

// Cuts `path` (created if missing) after its first `lines` lines, whose ends are `ends`.
void KeepLines(const fs::path& path, const std::vector<std::streamoff>& ends, size_t lines) {
  RefuseSymlink(path);  // resize_file would cut the link's target
  if (!fs::exists(path)) CloseChecked(OpenForWriting(path, "wb"), path);
  fs::resize_file(path, lines == 0 ? 0 : static_cast<uintmax_t>(ends[lines - 1]));
}

// One run's two lines, written together by the pipeline's serial stage.
struct RunLines {
  std::string decision;  // decisions.jsonl
  std::string result;    // results.jsonl
  bool ok = true;
  std::string cost;      // monitor_cost.jsonl
  RunRecord record;      // --early-stop: what the floors are judged on
};

// The complete lines of a file (a line cut by a crash is left out).
std::vector<std::string> CompleteLines(const fs::path& path) {
  std::vector<std::string> lines;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  while (std::getline(in, line) && !in.eof()) lines.push_back(line);
  return lines;
}

// --early-stop writes its runs in the order they ran; at the end the files (results.jsonl last,
// their lines in step) are rewritten in case order, as every other reader expects (a temporary
// file renamed over each).
void SortByCaseIndex(const std::vector<fs::path>& paths) {
  const std::vector<std::string> results = CompleteLines(paths.back());
  std::vector<std::pair<long, size_t>> order;
  for (size_t k = 0; k < results.size(); ++k) {
    order.emplace_back(RunRecordFromJson(nlohmann::json::parse(results[k])).case_index, k);
  }
  std::sort(order.begin(), order.end());
  for (const fs::path& path : paths) {
    const std::vector<std::string> lines = CompleteLines(path);
    std::string text;
    for (const auto& [index, k] : order) {
      if (k < lines.size()) text += lines[k] + "\n";
    }
    WriteAtomically(path, text);
  }
}

// The first `lines` complete lines of `path` (created if missing).
void KeepFirstLines(const fs::path& path, size_t lines) {
  std::vector<std::string> kept = CompleteLines(path);
  kept.resize(std::min(kept.size(), lines));
  std::string text;
  for (const std::string& line : kept) text += line + "\n";
  WriteAtomically(path, text);
}

// A case's fault family, as the early-stop floors count it: "" for a healthy case. A compound
// case's family is "compound": a faulty case for the overall floors, in no per_family scope
// (EarlyStop::Scope::Holds).
std::string FamilyOf(const CaseSpec& spec) { return spec.fault.is_null() ? std::string() : spec.fault.value("family", ""); }

// What the stages of one RunCampaign share: the directory's files, campaign.json as this run
// writes it, and the order of its cases (the shard's, or with --early-stop an even sweep of the
// case space and the floors that decide when to stop).
struct RunState {
  const Campaign& campaign;
  const RunnerOptions& options;
  fs::path campaign_path, results_path, decisions_path, cost_path;
  fs::path early_path;  // early_stop.json: marks a finished --early-stop run
  nlohmann::json campaign_file;
  std::unique_ptr<EarlyStop> early;     // --early-stop only
  std::optional<EarlyStopOrder> order;  // --early-stop only
  // The shard's cases, taken by index (CaseAt): nothing is held per case, so memory stays flat
  // in the campaign's size and the first run starts at once.
  size_t cases = 0;
};

// Creates the output directory and names its files; with --early-stop, the sweep and the floors
// (InputError with a shard: the floors are decided on all of the campaign's runs).
RunState StartRun(const Campaign& campaign, const RunnerOptions& o) {
  const fs::path dir(o.output_dir);
  fs::create_directories(dir);
  RunState run{campaign,
               o,
               dir / run_dir::kCampaign,
               dir / run_dir::kResults,
               dir / run_dir::kDecisions,
               dir / run_dir::kMonitorCost,
               dir / run_dir::kEarlyStop,
               CampaignFileJson(campaign, o.shard),
               nullptr,
               std::nullopt};
  if (o.early_stop) {
    if (o.shard.count > 1) {
      throw InputError("--early-stop", "",
                       "decides the campaign's floors on all of its runs in one directory, so it cannot run as a shard "
                       "(drop --shard, or run the shards without --early-stop)");
    }
    run.early = std::make_unique<EarlyStop>(campaign, *o.early_stop);
    run.order.emplace(CaseCount(campaign), campaign.seed);
    run.campaign_file["early_stop"] = o.early_stop->ToJson();
  }
  run.cases = static_cast<size_t>(o.shard.Size(CaseCount(campaign)));
  return run;
}

// The case index of the run's k-th case (k from 0).
long CaseIndexAt(const RunState& run, size_t k) {
  return run.order ? run.order->CaseIndex(static_cast<long>(k)) : run.options.shard.CaseIndex(static_cast<long>(k));
}

// --resume into a directory with results: its campaign.json must be this run's.
void RequireSameRun(const RunState& run) {
  if (!fs::exists(run.campaign_path) || ReadJsonFile(run.campaign_path.string()) != run.campaign_file) {
    throw InputError(run.campaign_path.string(), "",
                     "--resume: this directory holds another campaign or shard (or was run with other --early-stop "
                     "settings); run it without --resume, or choose another output directory");
  }
}

// A fresh run: campaign.json, the three line files empty, no early_stop.json of an earlier run
// into this directory.
void StartFresh(const RunState& run) {
  std::error_code ec;
  fs::remove(run.early_path, ec);
  WriteAtomically(run.campaign_path, run.campaign_file.dump(2) + "\n");
  for (const fs::path& path : {run.results_path, run.decisions_path, run.cost_path}) {
    CloseChecked(OpenForWriting(path, "wb"), path);
  }
}

// --resume of an ordinary run: keeps the complete prefix of lines that are exactly the expected
// cases, in order, in both files, and returns its length (the position to run on from).
// decisions.jsonl is written first, so after a kill it is at most one line ahead; a missing one
// (removed, or an older armfault's directory) keeps nothing. Sets out->resumed and out->failed.
size_t ResumeRun(const RunState& run, RunnerResult* out) {
  auto is_case = [&](size_t k, long case_index, const std::string& run_id) {
    const long index = CaseIndexAt(run, k);
    return case_index == index && run_id == CaseAt(run.campaign, index).run_id;
  };
  std::vector<bool> ok;
  const std::vector<std::streamoff> result_ends =
      AcceptedLineEnds(run.results_path, run.cases, [&](size_t k, const std::string& line) {
        try {
          const RunRecord r = RunRecordFromJson(nlohmann::json::parse(line));
          if (!is_case(k, r.case_index, r.run_id)) return false;
          ok.push_back(r.ok);
          return true;
        } catch (const std::exception&) {
          return false;
        }
      });
  const std::vector<std::streamoff> decision_ends =
      AcceptedLineEnds(run.decisions_path, result_ends.size(), [&](size_t k, const std::string& line) {
        try {
          const DecisionLine d = DecisionLineFromJson(nlohmann::json::parse(line));
          return is_case(k, d.case_index, d.run_id);
        } catch (const std::exception&) {
          return false;
        }
      });
  const size_t next = decision_ends.size();
  for (size_t k = 0; k < next; ++k) out->failed += ok[k] ? 0 : 1;
  KeepLines(run.results_path, result_ends, next);
  KeepLines(run.decisions_path, decision_ends, next);
  KeepFirstLines(run.cost_path, next);  // written before each results line: at least `next`
  out->resumed = static_cast<long>(next);
  return next;
}

// --resume of an --early-stop run not finished: replays the decisions over the runs kept so far,
// in the order they ran (each needed case in turn must be the next line of both files), keeps
// that prefix and returns the position in the sweep to run on from. Sets out->resumed and
// out->failed.
size_t ResumeEarlyStop(RunState& run, RunnerResult* out) {
  const std::vector<std::string> results_lines = CompleteLines(run.results_path),
                                 decision_lines = CompleteLines(run.decisions_path);
  const size_t lines = std::min(results_lines.size(), decision_lines.size());
  size_t next = 0, kept = 0;
  for (; next < run.cases && kept < lines && !run.early->AllDecided(); ++next) {
    const CaseSpec spec = CaseAt(run.campaign, CaseIndexAt(run, next));
    if (!run.early->Needed(FamilyOf(spec))) continue;
    RunRecord r;
    try {
      r = RunRecordFromJson(nlohmann::json::parse(results_lines[kept]));
      const DecisionLine d = DecisionLineFromJson(nlohmann::json::parse(decision_lines[kept]));
      if (r.case_index != spec.index || r.run_id != spec.run_id || d.case_index != spec.index) break;
    } catch (const std::exception&) {
      break;
    }
    run.early->Add(r);
    out->failed += r.ok ? 0 : 1;
    ++kept;
  }
  std::string results_text, decisions_text;
  for (size_t k = 0; k < kept; ++k) {
    results_text += results_lines[k] + "\n";
    decisions_text += decision_lines[k] + "\n";
  }
  WriteAtomically(run.decisions_path, decisions_text);
  KeepFirstLines(run.cost_path, kept);
  WriteAtomically(run.results_path, results_text);
  out->resumed = static_cast<long>(kept);
  return next;
}

// --resume of a finished --early-stop run (early_stop.json there): its files are in case order
// already and nothing is left to run. Counts its runs and reads its early_stop.json into `out`.
void ReadFinishedEarlyStop(const RunState& run, RunnerResult* out) {
  for (const std::string& line : CompleteLines(run.results_path)) {
    ++out->resumed;
    out->failed += RunRecordFromJson(nlohmann::json::parse(line)).ok ? 0 : 1;
  }
  out->early_stop = ReadJsonFile(run.early_path.string());
}

// A file the writer stage appends to, closed on every path: by Close, which says whether every
// write reached the file, or else (an exception) when it goes out of scope.
struct AppendFile {
  explicit AppendFile(const fs::path& p) : path(p), file(OpenForWriting(p, "ab")) {}
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;
  ~AppendFile() {
    if (file) std::fclose(file);
  }
  // One write per line, flushed at once: a kill leaves at most one partial line; a write the
  // file does not take (a full disk) stops the run with the system's reason.
  void Write(const std::string& line) { WriteChecked(file, line, path); }
  // The file's size now (every write is flushed), and cutting it back to such a size: what a
  // failed write took of its line goes, and so does what stdio still holds of it.
  off_t Size() const {
    struct stat st {};
    return ::fstat(::fileno(file), &st) == 0 ? st.st_size : -1;
  }
  void TrimTo(off_t size) {
    __fpurge(file);
    if (size >= 0 && ::ftruncate(::fileno(file), size) != 0) {
      // Nothing more to do: the write's error already stops the run; resume trims the rest.
    }
  }
  bool Close() {
    const bool closed = std::fclose(file) == 0;
    file = nullptr;
    return closed;
  }
  fs::path path;
  std::FILE* file;
};

// Holds an ExitGate (if any) for the scope: a run's lines are written whole or not at all.
struct GateHeld {
  explicit GateHeld(ExitGate* gate) : gate(gate) {
    if (gate) gate->Enter();
  }
  ~GateHeld() {
    if (gate) gate->Leave();
  }
  GateHeld(const GateHeld&) = delete;
  GateHeld& operator=(const GateHeld&) = delete;
  ExitGate* gate;
};

// The run's three line files, opened for appending in this order (a failed open closes those
// already open). Close closes all three, then names the first that lost a write.
struct RunFiles {
  explicit RunFiles(const RunState& run)
      : results(run.results_path), decisions(run.decisions_path), costs(run.cost_path) {}
  void Close() {
    const bool decisions_closed = decisions.Close();
    const bool costs_closed = costs.Close();
    if (!results.Close()) throw InputError(results.path.string(), "", "error while writing");
    if (!decisions_closed) throw InputError(decisions.path.string(), "", "error while writing");
    if (!costs_closed) throw InputError(costs.path.string(), "", "error while writing");
  }
  AppendFile results, decisions, costs;
};

// Runs the cases from position `next` on (oneTBB, the options' threads) and appends each run's
// lines to `files` in case order (in sweep order with --early-stop, dropping the runs no
// undecided floor needs). Sets out->ran, out->failed and out->interrupted; calls progress.
void RunCases(RunState& run, size_t next, RunFiles& files, RunnerResult* out) {
  const RunnerOptions& o = run.options;
  long done = out->resumed;
  if (o.progress) o.progress(done, out->total);
  std::mutex early_mutex;  // the input stage asks what the output stage decides
  size_t cursor = next;
  auto next_case = [&]() -> std::optional<size_t> {
    if (cursor >= run.cases) return std::nullopt;
    if (o.stop && o.stop->load()) {
      out->interrupted = true;
      return std::nullopt;
    }
    if (run.early) {
      // Skip the cases no undecided floor needs (decisions are final, so the output stage
      // would drop them too).
      std::lock_guard<std::mutex> lock(early_mutex);
      while (cursor < run.cases && !run.early->AllDecided() &&
             !run.early->Needed(FamilyOf(CaseAt(run.campaign, CaseIndexAt(run, cursor))))) {
        ++cursor;
      }
      if (cursor >= run.cases || run.early->AllDecided()) return std::nullopt;
    }
    return cursor++;
  };
  UnitMonitors units(run.campaign);
  auto run_case = [&](size_t k) {
    RunRecord r = RunCase(run.campaign, CaseAt(run.campaign, CaseIndexAt(run, k)), nullptr, &units);
    RunLines lines{DecisionLineJson(r).dump() + "\n", ToJson(r).dump() + "\n", r.ok, MonitorCostLine(r), {}};
    if (run.early) lines.record = std::move(r);
    return lines;
  };
  auto write = [&](const RunLines& item) {
    std::unique_lock<std::mutex> lock(early_mutex, std::defer_lock);
    if (run.early) {
      // In the order of the runs: a run no undecided floor needs any more is dropped,
      // whichever thread finished it when, so the kept runs are the same for any -j.
      lock.lock();
      if (run.early->AllDecided() || !run.early->Needed(item.record.family)) return;
      run.early->Add(item.record);
    }
    // The decision first: results.jsonl is never ahead of decisions.jsonl. A write that fails
    // (a full disk) takes the run's lines out of all three files again: no half line is left.
    const GateHeld held(o.exit_gate);
    const off_t sizes[3] = {files.decisions.Size(), files.costs.Size(), files.results.Size()};
    try {
      files.decisions.Write(item.decision);
      files.costs.Write(item.cost);
      files.results.Write(item.result);
    } catch (...) {
      files.decisions.TrimTo(sizes[0]);
      files.costs.TrimTo(sizes[1]);
      files.results.TrimTo(sizes[2]);
      throw;
    }
    if (!item.ok) ++out->failed;
    ++out->ran;
    ++done;
    if (o.progress) o.progress(done, out->total);
  };
  RunOrderedPipeline(o.threads, next_case, run_case, write);
}

// The end of a finished --early-stop run: its files rewritten in case order, and early_stop.json.
void FinishEarlyStop(const RunState& run, RunnerResult* out) {
  SortByCaseIndex({run.decisions_path, run.cost_path, run.results_path});
  out->early_stop = run.early->ToJson(CaseCount(run.campaign));
  WriteAtomically(run.early_path, out->early_stop.dump(2) + "\n");
}

}  // namespace

std::string EarlyStopSummaryLine(const nlohmann::json& report) {
  const long runs = report.at("runs").get<long>(), cases = report.at("cases").get<long>();
  std::string line = report.at("decided").get<bool>()
                         ? "early stop: every floor decided after " + std::to_string(runs) + " of " + std::to_string(cases) +
                               " runs (" + std::to_string(cases - runs) + " not run, " +
                               std::to_string(static_cast<int>(std::lround(100.0 * static_cast<double>(cases - runs) /
                                                                          static_cast<double>(std::max(1L, cases))))) +
                               " %)"
                         : "early stop: not every floor could be decided; all " + std::to_string(runs) + " runs made";
  for (const nlohmann::json& f : report.at("floors")) {
    char p[32];
    std::snprintf(p, sizeof p, "%.4f", f.at("p_met").get<double>());
    line += "\n  " + f.at("name").get<std::string>() + ": " +
            (f.at("decided").get<bool>() ? std::string(f.at("met").get<bool>() ? "met" : "missed") + " after " +
                                               std::to_string(f.at("decided_after_runs").get<long>()) + " runs"
                                         : std::string("undecided")) +
            " (P(met by the whole campaign) = " + p + ", " + std::to_string(f.at("successes").get<long>()) + " of " +
            std::to_string(f.at("trials").get<long>()) + ")";
  }
  return line;
}

RunnerResult RunCampaign(const Campaign& campaign, const RunnerOptions& o) {
  RunState run = StartRun(campaign, o);
  RunnerResult out;
  out.total = static_cast<long>(run.cases);
  const bool resume = o.resume && fs::exists(run.results_path);
  if (resume) RequireSameRun(run);
  if (resume && run.early && fs::exists(run.early_path)) {
    ReadFinishedEarlyStop(run, &out);
    return out;
  }
  size_t next = 0;
  if (resume && run.early) {
    next = ResumeEarlyStop(run, &out);
  } else if (resume) {
    next = ResumeRun(run, &out);
  } else {
    StartFresh(run);
  }
  RunFiles files(run);
  RunCases(run, next, files, &out);
  files.Close();
  if (run.early && !out.interrupted) FinishEarlyStop(run, &out);
  return out;
}

}  // namespace armfault
