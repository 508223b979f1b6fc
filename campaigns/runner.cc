#include "campaigns/runner.h"

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include "campaigns/early_stop.h"

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
  if (!fs::exists(path)) std::ofstream(path, std::ios::binary);
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

std::string CostLine(const RunRecord& r) {
  nlohmann::json j = {{"case", r.case_index}, {"run_id", r.run_id}};
  if (r.cost.is_object()) {
    j.update(r.cost);
  } else {
    j["ticks"] = 0;
  }
  return j.dump() + "\n";
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
  const fs::path dir(o.output_dir);
  fs::create_directories(dir);
  const fs::path campaign_path = dir / run_dir::kCampaign;
  const fs::path results_path = dir / run_dir::kResults;
  const fs::path decisions_path = dir / run_dir::kDecisions;
  const fs::path cost_path = dir / run_dir::kMonitorCost;
  nlohmann::json campaign_file = CampaignFileJson(campaign, o.shard);
  // --early-stop: the runs go in an even sweep of the case space and stop when every floor is
  // decided (campaigns/early_stop.h); early_stop.json marks a finished one.
  const fs::path early_path = dir / run_dir::kEarlyStop;
  std::unique_ptr<EarlyStop> early;
  std::optional<EarlyStopOrder> order;
  std::mutex early_mutex;  // the input stage asks what the output stage decides
  if (o.early_stop) {
    if (o.shard.count > 1) {
      throw InputError("--early-stop", "",
                       "decides the campaign's floors on all of its runs in one directory, so it cannot run as a shard "
                       "(drop --shard, or run the shards without --early-stop)");
    }
    early = std::make_unique<EarlyStop>(campaign, *o.early_stop);
    order.emplace(CaseCount(campaign), campaign.seed);
    campaign_file["early_stop"] = o.early_stop->ToJson();
  }
  auto case_at_position = [&](size_t k) {
    return order ? order->CaseIndex(static_cast<long>(k)) : o.shard.CaseIndex(static_cast<long>(k));
  };
  // A compound case's family is "compound": a faulty case for the overall floors, in no
  // per_family scope (EarlyStop::Scope::Holds).
  auto family_of = [](const CaseSpec& spec) { return spec.fault.is_null() ? std::string() : spec.fault.value("family", ""); };

  // The shard's cases by index (CaseAt): nothing is held per case, so memory stays flat in
  // the campaign's size and the first run starts at once.
  const size_t mine = static_cast<size_t>(o.shard.Size(CaseCount(campaign)));
  auto is_case = [&](size_t k, long case_index, const std::string& run_id) {
    const long index = case_at_position(k);
    return case_index == index && run_id == CaseAt(campaign, index).run_id;
  };
  RunnerResult out;
  out.total = static_cast<long>(mine);

  size_t next = 0;
  if (o.resume && fs::exists(results_path)) {
    if (!fs::exists(campaign_path) || ReadJsonFile(campaign_path.string()) != campaign_file) {
      throw InputError(campaign_path.string(), "",
                       "--resume: this directory holds another campaign or shard (or was run with other --early-stop "
                       "settings); run it without --resume, or choose another output directory");
    }
  }
  if (early && o.resume && fs::exists(results_path) && fs::exists(early_path)) {
    // Finished: its files are in case order already, and nothing is left to run.
    for (const std::string& line : CompleteLines(results_path)) {
      ++out.resumed;
      out.failed += RunRecordFromJson(nlohmann::json::parse(line)).ok ? 0 : 1;
    }
    out.early_stop = ReadJsonFile(early_path.string());
    return out;
  }
  if (early && o.resume && fs::exists(results_path)) {
    // Replay the decisions over the runs kept so far, in the order they ran: each needed case
    // in turn must be the next line of both files; keep that prefix.
    const std::vector<std::string> results_lines = CompleteLines(results_path), decision_lines = CompleteLines(decisions_path);
    const size_t lines = std::min(results_lines.size(), decision_lines.size());
    size_t kept = 0;
    for (; next < mine && kept < lines && !early->AllDecided(); ++next) {
      const CaseSpec spec = CaseAt(campaign, case_at_position(next));
      if (!early->Needed(family_of(spec))) continue;
      RunRecord r;
      try {
        r = RunRecordFromJson(nlohmann::json::parse(results_lines[kept]));
        const DecisionLine d = DecisionLineFromJson(nlohmann::json::parse(decision_lines[kept]));
        if (r.case_index != spec.index || r.run_id != spec.run_id || d.case_index != spec.index) break;
      } catch (const std::exception&) {
        break;
      }
      early->Add(r);
      out.failed += r.ok ? 0 : 1;
      ++kept;
    }
    std::string results_text, decisions_text;
    for (size_t k = 0; k < kept; ++k) {
      results_text += results_lines[k] + "\n";
      decisions_text += decision_lines[k] + "\n";
    }
    WriteAtomically(decisions_path, decisions_text);
    KeepFirstLines(cost_path, kept);
    WriteAtomically(results_path, results_text);
    out.resumed = static_cast<long>(kept);
  } else if (o.resume && fs::exists(results_path)) {
    // Keep the complete prefix of lines that are exactly the expected cases, in order, in both
    // files. decisions.jsonl is written first, so after a kill it is at most one line ahead; a
    // missing one (removed, or an older armfault's directory) keeps nothing.
    std::vector<bool> ok;
    const std::vector<std::streamoff> result_ends =
        AcceptedLineEnds(results_path, mine, [&](size_t k, const std::string& line) {
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
        AcceptedLineEnds(decisions_path, result_ends.size(), [&](size_t k, const std::string& line) {
          try {
            const DecisionLine d = DecisionLineFromJson(nlohmann::json::parse(line));
            return is_case(k, d.case_index, d.run_id);
          } catch (const std::exception&) {
            return false;
          }
        });
    next = decision_ends.size();
    for (size_t k = 0; k < next; ++k) out.failed += ok[k] ? 0 : 1;
    KeepLines(results_path, result_ends, next);
    KeepLines(decisions_path, decision_ends, next);
    KeepFirstLines(cost_path, next);  // written before each results line: at least `next`
    out.resumed = static_cast<long>(next);
  } else {
    std::error_code ec;
    fs::remove(early_path, ec);  // of an earlier run into this directory
    WriteAtomically(campaign_path, campaign_file.dump(2) + "\n");
    std::ofstream(results_path, std::ios::binary | std::ios::trunc);
    std::ofstream(decisions_path, std::ios::binary | std::ios::trunc);
    std::ofstream(cost_path, std::ios::binary | std::ios::trunc);
  }

  std::FILE* results = std::fopen(results_path.string().c_str(), "ab");
  if (!results) throw InputError(results_path.string(), "", "cannot open for appending");
  std::FILE* decisions = std::fopen(decisions_path.string().c_str(), "ab");
  if (!decisions) {
    std::fclose(results);
    throw InputError(decisions_path.string(), "", "cannot open for appending");
  }
  std::FILE* costs = std::fopen(cost_path.string().c_str(), "ab");
  if (!costs) {
    std::fclose(results);
    std::fclose(decisions);
    throw InputError(cost_path.string(), "", "cannot open for appending");
  }
  long done = out.resumed;
  if (o.progress) o.progress(done, out.total);

  UnitMonitors units(campaign);
  const int threads = o.threads > 0 ? o.threads : tbb::this_task_arena::max_concurrency();
  tbb::task_arena arena(threads);
  arena.execute([&] {
    size_t cursor = next;
    tbb::parallel_pipeline(
        static_cast<size_t>(4 * threads),
        tbb::make_filter<void, size_t>(tbb::filter_mode::serial_in_order,
                                       [&](tbb::flow_control& fc) -> size_t {
                                         if (cursor >= mine) {
                                           fc.stop();
                                           return 0;
                                         }
                                         if (o.stop && o.stop->load()) {
                                           out.interrupted = true;
                                           fc.stop();
                                           return 0;
                                         }
                                         if (early) {
                                           // Skip the cases no undecided floor needs (decisions are final,
                                           // so the output stage would drop them too).
                                           std::lock_guard<std::mutex> lock(early_mutex);
                                           while (cursor < mine && !early->AllDecided() &&
                                                  !early->Needed(family_of(CaseAt(campaign, case_at_position(cursor))))) {
                                             ++cursor;
                                           }
                                           if (cursor >= mine || early->AllDecided()) {
                                             fc.stop();
                                             return 0;
                                           }
                                         }
                                         return cursor++;
                                       }) &
            tbb::make_filter<size_t, RunLines>(tbb::filter_mode::parallel,
                                               [&](size_t k) {
                                                 RunRecord r = RunCase(campaign, CaseAt(campaign, case_at_position(k)),
                                                                       nullptr, &units);
                                                 RunLines lines{DecisionLineJson(r).dump() + "\n", ToJson(r).dump() + "\n",
                                                                r.ok, CostLine(r), {}};
                                                 if (early) lines.record = std::move(r);
                                                 return lines;
                                               }) &
            tbb::make_filter<RunLines, void>(tbb::filter_mode::serial_in_order, [&](const RunLines& item) {
              std::unique_lock<std::mutex> lock(early_mutex, std::defer_lock);
              if (early) {
                // In the order of the runs: a run no undecided floor needs any more is dropped,
                // whichever thread finished it when, so the kept runs are the same for any -j.
                lock.lock();
                if (early->AllDecided() || !early->Needed(item.record.family)) return;
                early->Add(item.record);
              }
              // One write per line, flushed at once, the decision first: a kill leaves at most one
              // partial line in each file, and results.jsonl never ahead of decisions.jsonl.
              std::fwrite(item.decision.data(), 1, item.decision.size(), decisions);
              std::fflush(decisions);
              std::fwrite(item.cost.data(), 1, item.cost.size(), costs);
              std::fflush(costs);
              std::fwrite(item.result.data(), 1, item.result.size(), results);
              std::fflush(results);
              if (!item.ok) ++out.failed;
              ++out.ran;
              ++done;
              if (o.progress) o.progress(done, out.total);
            }));
  });
  const bool decisions_closed = std::fclose(decisions) == 0;
  const bool costs_closed = std::fclose(costs) == 0;
  if (std::fclose(results) != 0) throw InputError(results_path.string(), "", "error while writing");
  if (!decisions_closed) throw InputError(decisions_path.string(), "", "error while writing");
  if (!costs_closed) throw InputError(cost_path.string(), "", "error while writing");
  if (early && !out.interrupted) {
    SortByCaseIndex({decisions_path, cost_path, results_path});
    out.early_stop = early->ToJson(CaseCount(campaign));
    WriteAtomically(early_path, out.early_stop.dump(2) + "\n");
  }
  return out;
}

}  // namespace armfault
