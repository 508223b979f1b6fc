// Gathering the campaign report's data (reports/page/campaign_report.h) from an output directory:
// summary.json, campaign.json, results.jsonl, tuning.json, boundary.json, thesis.json, each
// checked to be of one campaign, and the plotted run re-simulated.
#include "reports/page/report_data.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "campaigns/scoring/provenance.h"
#include "campaigns/data/replay.h"
#include "campaigns/running/run_dir.h"
#include "campaigns/running/run_pipeline.h"
#include "campaigns/tuning/tuning.h"
#include "core/base/json_input.h"
#include "faults/fault.h"
#include "reports/page/report_common.h"

namespace armfault {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using report::Count;
using report::Field;
using report::Fixed;
using report::Num;

// One faulty run's outcome into its family's detection as run.
void AddPodRun(const RunRecord& r, PodAsRun* p) {
  PodAsRun::Cell* cell = nullptr;
  if (!r.magnitude_key.empty()) {
    p->magnitude_key = r.magnitude_key;
    cell = &p->by_magnitude[r.magnitude];
    const double severity = FaultSeverity(r.magnitude_key, r.magnitude);
    if (severity > 0 && std::isfinite(severity)) {
      p->severities.push_back(severity);
      p->hits.push_back(r.detected);
    }
  } else {
    if (p->name_key.empty() && r.fault.is_object()) {
      for (const char* key : {"lead", "kind"}) {
        if (r.fault.contains(key) && r.fault[key].is_string()) {
          p->name_key = key;
          break;
        }
      }
    }
    cell = &p->by_name[PodCategory(r.fault)];
  }
  ++cell->runs;
  cell->detected += r.detected ? 1 : 0;
  std::vector<std::string>& ids = r.detected ? cell->hit_ids : cell->miss_ids;
  std::vector<int>& joints = r.detected ? cell->hit_joints : cell->miss_joints;
  if (ids.size() < PodAsRun::kMaxListed) ids.push_back(r.run_id), joints.push_back(r.joint);
}

}  // namespace

std::optional<nlohmann::json> ReadTuning(const std::string& dir) {
  const fs::path path = fs::path(dir) / "tuning.json";
  if (!fs::exists(path)) return std::nullopt;
  return ReadJsonFile(path.string());
}

std::optional<nlohmann::json> TuningOrDefault(const std::string& dir) {
  if (std::optional<nlohmann::json> stored = ReadTuning(dir)) return stored;
  return TuneCampaignDir(dir, TuneOptions()).report;
}

RunSeries SimulateRunSeries(const Campaign& campaign, const CaseSpec& spec) {
  RunSeries s;
  s.run_id = spec.run_id;
  const int joints = static_cast<int>(campaign.robot.modules.size());
  // Every joint of the robot, the faulted one first: a fault on one joint shows on the others too
  // (coupling), and a misnamed run is named on another.
  if (!spec.fault.is_null() && spec.fault.contains("joint") && spec.fault["joint"].is_number_integer()) {
    const int faulted = spec.fault["joint"].get<int>();
    if (faulted >= 1 && faulted <= joints) s.joints.push_back(faulted);
  }
  for (int j = 1; j <= joints; ++j) {
    if (std::find(s.joints.begin(), s.joints.end(), j) == s.joints.end()) s.joints.push_back(j);
  }
  s.i_cmd_A.resize(s.joints.size());
  s.i_supply_A.resize(s.joints.size());
  s.tau_sensor_Nm.resize(s.joints.size());
  // The run as the campaign ran it (campaigns/running/run_pipeline.h), with its own monitor's output.
  const TickObserver observer = [&](const Tick& tick) {
    s.t_s.push_back(tick.t_s);
    for (size_t k = 0; k < s.joints.size(); ++k) {
      const JointTick& jt = (*tick.joints)[s.joints[k] - 1];
      s.i_cmd_A[k].push_back(jt.signals.i_cmd_A);
      s.i_supply_A[k].push_back(jt.signals.i_supply_meas_A);
      s.tau_sensor_Nm[k].push_back(jt.signals.tau_sensor_Nm);
    }
  };
  s.record = RunCase(campaign, spec, observer, nullptr, &s.monitor);
  for (const Verdict& v : s.monitor.verdicts) {
    if (v.alarm) {
      s.first_alarm_s = v.t_s;
      s.first_alarm_family = v.family;
      break;
    }
  }
  if (!s.record.ok) s.error = s.record.failure_reason;
  return s;
}

namespace {

// summary.json and campaign.json: the campaign every other file must be of.
struct CampaignFiles {
  fs::path campaign_path;
  std::optional<Campaign> campaign;
  std::string campaign_error;         // why there is no campaign
  std::vector<CampaignClaim> claims;  // the campaign_hash of each file read so far
  std::optional<ReplaySource> replay;  // DIR/replay.json's source, when DIR is replay's output
  std::optional<RecordedRuns> recorded;  // a replay of an import: the runs its records must be
};

// Reads DIR/summary.json into d (and the campaign hash and the files that carry it) and
// DIR/campaign.json. Throws InputError without summary.json or when the two disagree.
CampaignFiles ReadSummaryAndCampaign(const ReportOptions& options, ReportData* d_out) {
  ReportData& d = *d_out;
  CampaignFiles files;
  const fs::path dir(options.dir);
  const fs::path summary_path = dir / "summary.json";
  if (!fs::exists(summary_path)) {
    // An interrupted run has its runs but no summary yet: --resume finishes it.
    std::error_code ec;
    if (fs::exists(dir / "campaign.json") && fs::file_size(dir / "results.jsonl", ec) > 0 && !ec) {
      throw InputError(summary_path.string(), "",
                       "no such file: the run in " + options.dir + " was interrupted before its summary; finish it with "
                       "`armfault run CAMPAIGN -o " + options.dir + " --resume`");
    }
    throw InputError(summary_path.string(), "", "no such file: run `armfault run CAMPAIGN -o " + options.dir + "` first");
  }
  d.summary = ReadJsonFile(summary_path.string());

  // campaign.json: the campaign every other file must be of, and the one the plotted run is
  // re-simulated from. A campaign that does not parse here (a moved csv trajectory) still
  // names its campaign; only the run section says what went wrong.
  files.campaign_path = dir / "campaign.json";
  const fs::path& campaign_path = files.campaign_path;
  if (fs::exists(campaign_path)) {
    const json file = ReadJsonFile(campaign_path.string());
    files.claims.push_back({campaign_path.string(), ClaimedCampaignHash(file, campaign_path.string()), ""});
    try {
      if (!file.is_object() || !file.contains("campaign")) {
        throw InputError(campaign_path.string(), "", "no \"campaign\" key: not written by `armfault run`");
      }
      // Relative file names (csv trajectories) resolve against DIR: the campaign's own folder is not recorded.
      files.campaign = CampaignFromJson(file["campaign"], campaign_path.string(), options.dir);
    } catch (const InputError& e) {
      files.campaign_error = e.what();
    }
  } else {
    files.campaign_error = campaign_path.string() + ": no such file";
  }
  files.claims.push_back({summary_path.string(), ClaimedCampaignHash(d.summary, summary_path.string()),
                    "summary.json is stale or was copied from elsewhere: run the campaign into " + options.dir +
                        " again (or merge its shards there)"});
  RequireOneCampaign(files.claims);
  files.replay = ReadReplaySource(options.dir);
  if (files.replay && files.replay->import) {
    files.recorded = ReplayedImportRuns(options.dir);
    d.recorded_runs = "the runs are recorded (replayed from the import " + files.replay->dir +
                      "), and its campaign.json is a stand-in that cannot re-simulate them: compare a recorded "
                      "run with a simulation with --twin ROBOT";
  }
  for (const CampaignClaim& c : files.claims) {
    if (!c.hash) continue;
    if (d.campaign_hash.empty()) d.campaign_hash = *c.hash;
    d.hashed_files.push_back(fs::path(c.file).filename().string());
  }
  return files;
}

// The runs of results.jsonl that may be plotted (case order).
struct RunCandidates {
  std::optional<RunRecord> first, first_missed, first_detected, wanted;  // wanted: --run's
};

// results.jsonl: latencies and detection as run per family into d, and the candidates for the
// plotted run. Each line must be a case of campaign.json (InputError naming the line).
RunCandidates ReadResults(const ReportOptions& options, const CampaignFiles& files, ReportData* d_out) {
  ReportData& d = *d_out;
  const fs::path dir(options.dir);
  const fs::path& campaign_path = files.campaign_path;
  const std::optional<Campaign>& campaign = files.campaign;
  std::optional<CaseMatcher> matcher;
  if (campaign) matcher.emplace(*campaign, files.recorded);
  if (campaign) d.not_excited_included = campaign->include_not_excited;
  RunCandidates candidates;
  {
    const fs::path path = dir / run_dir::kResults;
    JsonLinesOptions lines;
    lines.open_error = "cannot read the file (run `armfault run` first)";
    lines.skip_blank = true;
    ReadRunRecords(path, lines, [&](RunRecord&& r, long) {
      if (matcher) {
        if (const std::string why = matcher->Mismatch(r); !why.empty()) {
          throw std::runtime_error(why + matcher->NotOf(campaign_path.string(), options.dir));
        }
      }
      ++d.records;
      if (!candidates.first) candidates.first = r;
      if (!options.run_id.empty() && r.run_id == options.run_id) candidates.wanted = r;
      if (r.ok && !r.miss_reason.empty() && (r.family.empty() || r.excited() || d.not_excited_included)) {
        if (d.wrong.size() < ReportData::kListedRuns) d.wrong.push_back({r.run_id, r.miss_reason});
        ++d.wrong_count;
      }
      if (!r.ok || r.family.empty()) return;
      if (!r.injected()) return;  // its onset condition never fired: as summary.json, outside the rates
      if (!r.excited()) {
        if (d.not_excited.size() < ReportData::kListedRuns) d.not_excited.push_back({r.run_id, r.not_excited_reason});
        ++d.not_excited_count;
        if (!d.not_excited_included) return;  // as summary.json: outside the rates
      }
      if (!r.is_compound()) AddPodRun(r, &d.pod[r.family]);  // no single magnitude to plot against
      if (r.detected) {
        if (r.latency_s && std::isfinite(*r.latency_s)) {
          d.latencies_s[r.family].push_back(*r.latency_s);
          d.latency_runs[r.family].emplace_back(r.run_id, r.joint);
        }
        if (!candidates.first_detected) candidates.first_detected = r;
      } else {
        ++d.misses[r.family];
        if (!candidates.first_missed) candidates.first_missed = r;
      }
    });
  }
  return candidates;
}

// Tuning into d: DIR/tuning.json must be of this campaign; without one, the tuner's defaults.
void ReadTuningResults(const ReportOptions& options, std::vector<CampaignClaim>* claims_io, ReportData* d_out) {
  ReportData& d = *d_out;
  std::vector<CampaignClaim>& claims = *claims_io;
  const fs::path dir(options.dir);
  const fs::path tuning_path = dir / "tuning.json";
  const bool tuning_file = fs::exists(tuning_path);
  const std::string tune_hint = "run `armfault tune " + options.dir + "`";
  if (options.tuning) {
    try {
      d.tuning = options.tuning(options.dir);
    } catch (const InputError& e) {
      if (tuning_file) throw;
      d.tuning_source = tuning_path.string() + " is absent, and tuning with the defaults failed (" + e.what() + "): " +
                        tune_hint + " with another rule or sweep";
    }
  }
  if (d.tuning) {
    d.tuning_source = tuning_file ? tuning_path.string()
                                  : "computed now with the tuner's defaults (" + tuning_path.string() +
                                        " is absent: " + tune_hint + " to write it or to choose another rule)";
    const std::string name = tuning_file ? tuning_path.string() : "the tuning computed for " + options.dir;
    claims.push_back({name, ClaimedCampaignHash(*d.tuning, name),
                      tune_hint + " to tune this directory's campaign again (it rewrites tuning.json)"});
    RequireOneCampaign(claims);
    if (!d.campaign_hash.empty() && tuning_file) d.hashed_files.push_back("tuning.json");
  } else if (d.tuning_source.empty()) {
    d.tuning_source = tuning_path.string() + " is absent: " + tune_hint;
  }
}

// boundary.json (`armfault boundary`) into d, when there: of this campaign too.
void ReadBoundary(const ReportOptions& options, std::vector<CampaignClaim>* claims_io, ReportData* d_out) {
  ReportData& d = *d_out;
  std::vector<CampaignClaim>& claims = *claims_io;
  const fs::path dir(options.dir);
  const fs::path boundary_path = dir / "boundary.json";
  if (fs::exists(boundary_path)) {
    json b = ReadJsonFile(boundary_path.string());
    claims.push_back({boundary_path.string(), ClaimedCampaignHash(b, boundary_path.string()),
                      "run `armfault boundary` into " + options.dir + " again (or `armfault boundary --from " +
                          options.dir + "`)"});
    RequireOneCampaign(claims);
    if (!d.campaign_hash.empty()) d.hashed_files.push_back("boundary.json");
    d.boundary = std::move(b);
  }
}

// Thesis table 5-3 into d: the directory's own, else simulated; not for a campaign whose robot
// is not built from the thesis's modules (the table is about mrr-config1's top joint).
void ReadThesisTable(const ReportOptions& options, const CampaignFiles& files, ReportData* d_out) {
  ReportData& d = *d_out;
  const fs::path dir(options.dir);
  const fs::path thesis_path = dir / "thesis.json";
  if (fs::exists(thesis_path)) {
    const json t = ReadJsonFile(thesis_path.string());
    d.thesis_source = thesis_path.string();
    if (const json* rows = Field(t, "table_5_3"); rows != nullptr && rows->is_array()) {
      for (const json& row : *rows) {
        ThesisRow r;
        r.factor = Num(row, "kt_factor").value_or(std::nan(""));
        r.label = "n = " + Fixed(r.factor, 1);
        r.thesis_pct = Num(row, "thesis_pct").value_or(std::nan(""));
        r.armfault_pct = Num(row, "armfault_pct").value_or(std::nan(""));
        r.thesis_ratio = Num(row, "thesis_ratio").value_or(std::nan(""));
        r.armfault_ratio = Num(row, "armfault_ratio").value_or(std::nan(""));
        r.windows = static_cast<int>(Count(row, "windows"));
        r.ok = Field(row, "failure") == nullptr;
        d.table_5_3.push_back(r);
      }
    }
  } else if (files.campaign && std::any_of(files.campaign->robot.modules.begin(), files.campaign->robot.modules.end(),
                                           [](const ModuleParams& m) { return m.type != "MRR1" && m.type != "MRR2"; })) {
    d.thesis_source = "not shown: the thesis's table is about mrr-config1's top joint, and this campaign's robot \"" +
                      files.campaign->robot.name + "\" is not built from the thesis's modules";
  } else {
    const ThesisResults t = RunThesisExperiments(options.thesis_seed);
    d.thesis_source = "simulated now with seed " + std::to_string(options.thesis_seed) +
                      " (no thesis.json in the directory)";
    if (!t.experiments.empty()) d.table_5_3 = t.experiments[0].rows;
  }
}

// The plotted run into d.run: --run's, else chosen from the candidates, re-simulated. Throws
// InputError for an unknown --run, or --run without a campaign to re-simulate it from.
void SimulateChosenRun(const ReportOptions& options, const CampaignFiles& files, const RunCandidates& candidates,
                       ReportData* d_out) {
  ReportData& d = *d_out;
  const fs::path& campaign_path = files.campaign_path;
  const std::optional<Campaign>& campaign = files.campaign;
  const std::string& campaign_error = files.campaign_error;
  const std::optional<RunRecord>&first = candidates.first, &first_missed = candidates.first_missed,
                             &first_detected = candidates.first_detected, &wanted = candidates.wanted;
  RunSeries& s = d.run;
  const std::optional<RunRecord>& chosen =
      !options.run_id.empty() ? wanted : first_missed ? first_missed : first_detected ? first_detected : first;
  s.why = !options.run_id.empty() ? "chosen with --run"
          : first_missed          ? "the first faulty run that was missed"
          : first_detected        ? "the first faulty run (every faulty run was detected)"
                                  : "the first run (no faulty runs)";
  s.run_id = !options.run_id.empty() ? options.run_id : chosen ? chosen->run_id : "";
  if (!d.recorded_runs.empty()) {  // the section says why it is empty
    if (!options.run_id.empty()) throw InputError("--run", "", "cannot re-simulate run \"" + s.run_id + "\": " + d.recorded_runs);
    return;
  }
  if (!campaign) {
    if (!options.run_id.empty()) throw InputError("--run", "", "cannot re-simulate: " + campaign_error);
    s.error = campaign_error;
    return;
  }
  if (s.run_id.empty()) {
    s.error = "results.jsonl holds no runs";
    return;
  }
  const std::vector<CaseSpec> cases = ExpandCases(*campaign);
  auto it = std::find_if(cases.begin(), cases.end(), [&](const CaseSpec& c) { return c.run_id == s.run_id; });
  if (it == cases.end()) {
    throw InputError("--run", "", "no run \"" + s.run_id + "\" in " + campaign_path.string() +
                                      " (run ids look like \"" + (cases.empty() ? "" : cases.front().run_id) + "\")");
  }
  const std::string why = s.why;
  s = SimulateRunSeries(*campaign, *it);
  s.why = why;
  s.stored = chosen;
}

// The missed and misnamed faulty runs among d.wrong (case order), the first
// ReportData::kSmallMultiples of them re-simulated into d.wrong_runs.
void SimulateWrongRuns(const CampaignFiles& files, ReportData* d_out) {
  ReportData& d = *d_out;
  if (!files.campaign || d.wrong.empty() || !d.recorded_runs.empty()) return;
  std::map<std::string, const CaseSpec*> by_id;
  const std::vector<CaseSpec> cases = ExpandCases(*files.campaign);
  for (const CaseSpec& c : cases) by_id[c.run_id] = &c;
  for (const ReportData::ListedRun& w : d.wrong) {
    auto it = by_id.find(w.run_id);
    if (it == by_id.end() || it->second->fault.is_null()) continue;  // a healthy run that alarmed
    if (d.wrong_runs.size() >= ReportData::kSmallMultiples) break;
    RunSeries s = SimulateRunSeries(*files.campaign, *it->second);
    s.why = w.reason;
    d.wrong_runs.push_back(std::move(s));
  }
}

// The twin against one recorded run (ReportOptions::twin) into d.twin.
void CompareTwin(const ReportOptions& options, const CampaignFiles& files, ReportData* d_out) {
  if (!options.twin) return;
  TwinCompareOptions o = *options.twin;
  if (o.recorded_dir.empty()) {
    const fs::path dir(options.dir);
    const fs::path parent = fs::absolute(dir).lexically_normal().parent_path();
    if (fs::exists(dir / "manifest.jsonl")) {
      o.recorded_dir = dir.string();
    } else if (files.replay) {  // replay.json names the source: no guessing
      o.recorded_dir = files.replay->dir;
    } else if (fs::exists(parent / "manifest.jsonl")) {
      fs::path up = (dir / "..").lexically_normal();
      if (up.filename().empty() && up.has_parent_path()) up = up.parent_path();  // "out/" as "out"
      o.recorded_dir = up.string();
    } else {
      throw InputError("--recorded", "", "no manifest.jsonl in " + options.dir + " nor in " + parent.string() +
                                             ": name the export or import whose runs " + options.dir +
                                             " replayed with --recorded DIR");
    }
  }
  d_out->twin = CompareRecordedRun(o);
}

}  // namespace

ReportData GatherReportData(const ReportOptions& options) {
  ReportData d;
  d.dir = options.dir;
  CampaignFiles files = ReadSummaryAndCampaign(options, &d);
  const RunCandidates candidates = ReadResults(options, files, &d);
  CompareTwin(options, files, &d);
  ReadTuningResults(options, &files.claims, &d);
  ReadBoundary(options, &files.claims, &d);
  ReadThesisTable(options, files, &d);
  SimulateChosenRun(options, files, candidates, &d);
  SimulateWrongRuns(files, &d);
  return d;
}

}  // namespace armfault
