// `armfault trace CAMPAIGN.json --run RUN_ID`: one case of a campaign re-run exactly as the
// campaign ran it (the same RunCase, seed, variation and fault), with its time series written
// as a trace CSV and its record printed, to look into one run of a campaign's results.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/base/output_file.h"
#include "app/commands/commands.h"
#include "core/base/suggest.h"
#include "campaigns/spec/campaign.h"
#include "campaigns/running/runner.h"
#include "core/base/json_input.h"
#include "reports/statistics_csv.h"
#include "reports/trace_csv.h"

namespace armfault {

namespace {

// The run_id nearest to `id`: among the ids sharing the longest prefix with it (a typo is
// usually in a value or the repetition near the end), the one with the fewest edits. Bounded
// work for campaigns of millions of runs.
// The run_id nearest to `id` (core/base/suggest.h, NearestId); only on the error path.
std::string Nearest(const std::vector<CaseSpec>& cases, const std::string& id) {
  std::vector<std::string> ids;
  ids.reserve(cases.size());
  for (const CaseSpec& c : cases) ids.push_back(c.run_id);
  return NearestId(id, ids);
}

const CaseSpec& FindCase(const std::vector<CaseSpec>& cases, const std::string& id) {
  // A case number (results.jsonl's "case"): run_ids always hold a '/', so no clash.
  if (std::all_of(id.begin(), id.end(), [](unsigned char ch) { return std::isdigit(ch); })) {
    const unsigned long long k = id.size() > 18 ? ~0ULL : std::stoull(id);
    if (k >= cases.size()) {
      throw InputError("--run", "", "case " + id + " does not exist: the campaign's cases are 0.." +
                                        std::to_string(cases.size() - 1));
    }
    return cases[k];
  }
  for (const CaseSpec& c : cases) {
    if (c.run_id == id) return c;
  }
  std::string first;
  for (size_t k = 0; k < cases.size() && k < 3; ++k) first += (k ? ", \"" : "\"") + cases[k].run_id + "\"";
  throw InputError("--run", "", "no run \"" + id + "\" in this campaign; did you mean \"" + Nearest(cases, id) +
                                    "\"? (its first runs: " + first + (cases.size() > 3 ? ", ..." : "") +
                                    "; or give a case number 0.." + std::to_string(cases.size() - 1) + ")");
}

void PrintRecord(const RunRecord& r) {
  if (!r.ok) {
    std::printf("result: failed: %s\n", r.failure_reason.c_str());
  } else if (!r.detected) {
    std::printf("result: not detected%s\n", r.alarm_before_onset ? " (an alarm before the onset)" : "");
  } else {
    std::printf("result: detected at %.3f s", r.detection_time_s.value_or(0));
    if (r.latency_s) std::printf(" (latency %.3f s)", *r.latency_s);
    std::printf(": %s, joint %d", r.isolated_family.empty() ? "unknown family" : r.isolated_family.c_str(),
                r.isolated_joint);
    if (r.magnitude_estimate) std::printf(", %s %.4g", r.magnitude_name.c_str(), *r.magnitude_estimate);
    std::printf(" (confidence %.2f)%s\n", r.confidence, r.alarm_before_onset ? ", and an alarm before the onset" : "");
  }
  if (!r.family.empty()) {
    std::printf("truth: %s, joint %d, onset %.3f s", r.family.c_str(), r.joint, r.onset_s);
    if (!r.magnitude_key.empty()) std::printf(", %s %.4g", r.magnitude_key.c_str(), r.magnitude);
    std::printf("\n");
  } else {
    std::printf("truth: healthy\n");
  }
  // The whole record, as the campaign's results.jsonl line for this run.
  std::printf("record: %s\n", ToJson(r).dump().c_str());
}

}  // namespace

void PrintStatistics(const StatisticsCsvWriter& statistics, const std::string& file) {
  if (statistics.statistics().empty()) {
    std::printf("statistics: the monitor publishes none (docs/monitor-api.md, \"Statistics for tune\") -> %s\n",
                file.c_str());
    return;
  }
  std::string names;
  for (const PublishedStatistic& s : statistics.statistics()) names += (names.empty() ? "" : ", ") + s.name;
  std::printf("statistics: %s -> %s\n", names.c_str(), file.c_str());
}

int TraceCampaignCase(const TraceOptions& o) {
  if (o.run_file.empty()) throw InputError("--run", "", "give the campaign: armfault trace CAMPAIGN.json --run RUN_ID");
  if (!o.robot.empty() || o.duration_s || o.seed || !o.joint_specs.empty() || !o.fault_specs.empty()) {
    throw InputError("--run", "", "the case runs as the campaign ran it: --robot, --duration, --seed, --joint and "
                                  "--fault do not apply");
  }
  // A campaign file, or the campaign.json of a campaign's output directory (which wraps the
  // resolved campaign with the version and shard).
  const nlohmann::json input = ReadJsonFile(o.run_file);
  const bool output_dir_file = input.is_object() && input.contains("armfault_version") && input.contains("campaign");
  const std::string base = std::filesystem::path(o.run_file).parent_path().string();
  const Campaign campaign = output_dir_file ? CampaignFromJson(input["campaign"], o.run_file, base.empty() ? "." : base)
                                            : ReadCampaignFile(o.run_file);
  const std::vector<CaseSpec> cases = ExpandCases(campaign);
  const CaseSpec& spec = FindCase(cases, o.run_id);

  AtomicOutputFile file(o.output);  // the trace appears whole, or not at all
  TraceCsvWriter writer([&file](std::string_view text) { file.Write(text); },
                        static_cast<int>(campaign.robot.modules.size()));
  // The run's own monitor's output, for --monitor-out.
  MonitorOutput output;
  // --statistics: every published statistic at every tick, whole or not at all, as the trace.
  std::unique_ptr<AtomicOutputFile> statistics_file;
  std::unique_ptr<StatisticsCsvWriter> statistics;
  if (!o.statistics_output.empty()) {
    statistics_file = std::make_unique<AtomicOutputFile>(o.statistics_output);
    statistics = std::make_unique<StatisticsCsvWriter>([&](std::string_view text) { statistics_file->Write(text); });
  }
  const RunRecord record =
      RunCase(campaign, spec, [&](const Tick& tick) { writer.Write(tick); }, nullptr, &output, statistics.get());
  file.Commit();
  if (statistics_file) {
    if (!statistics->declared()) statistics->Declare({}, static_cast<int>(campaign.robot.modules.size()));
    statistics_file->Commit();
  }
  WriteTraceChannels(o.output, static_cast<int>(campaign.robot.modules.size()));  // what each column is, beside it

  if (!o.monitor_output.empty()) {
    nlohmann::json out = ToJson(output);
    out["record"] = ToJson(record);
    WriteAtomically(o.monitor_output, out.dump(1) + "\n");
  }
  if (!o.quiet) {
    std::printf("campaign %s: run %s (case %ld of %zu), seed %llu -> %s\n", campaign.name.c_str(), spec.run_id.c_str(),
                spec.index, cases.size(), spec.seed, o.output.c_str());
    std::printf("fault: %s\n", spec.fault.is_null() ? "none" : spec.fault.dump().c_str());
    PrintRecord(record);
    if (statistics) PrintStatistics(*statistics, o.statistics_output);
  }
  if (!record.ok) {
    std::fprintf(stderr, "armfault: run failed: %s\n", record.failure_reason.c_str());
    return 3;
  }
  return 0;
}

}  // namespace armfault
