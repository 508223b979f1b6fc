// Labeled data for data-driven detectors, and scoring of verdicts made offline.
//
// `armfault export CAMPAIGN -o DIR` runs every case of a campaign (sharded like `run`) and
// writes, per run, what a monitor may read — every joint's JointSignals at every controller
// tick — with the ground truth in a manifest:
//   DIR/campaign.json        the resolved campaign (as `run` writes it)
//   DIR/manifest.jsonl       one line per run, case order: run_id, split, signals file, fault
//                            (family, joint, onset_s, magnitude, profile), unit, variation drawn,
//                            took-effect measure, not_excited_reason, status
//   DIR/manifest.csv         the same, flat (scalar columns only), for pandas
//   DIR/runs/<case>.csv.gz   t_s, then <field>_j<joint> for every JointSignals field and joint;
//                            numbers in shortest round-trip form (exact doubles), empty = NaN
//   DIR/channels.json        each column of runs/*.csv.gz: name, unit, source, joint
//                            (campaigns/data/channels.h)
// See docs/monitor-api.md, "Export and score".
//
// `armfault score DIR VERDICTS` reads verdicts made by any tool (JSON Lines: run_id, t_s,
// joint, family, alarm, magnitude, and optionally state, magnitude_name, confidence) and scores
// them against DIR's truth (an export's manifest.jsonl, or a run's results.jsonl) exactly as a
// live monitor is scored (ScoreVerdicts), writing results.jsonl for the summary, JUnit and
// report.
#pragma once

#include <functional>
#include <istream>
#include <string>
#include <vector>

#include "campaigns/spec/campaign.h"
#include "campaigns/scoring/run_record.h"
#include "campaigns/running/runner.h"

namespace armfault {

// The JointSignals fields in column order, with units in their names.
const std::vector<std::string>& SignalColumnNames();
// The CSV header of a run's signals: "t_s,q_ref_rad_j1,...".
std::string SignalsCsvHeader(int joints);

// manifest.csv's header line and the row of one manifest.jsonl line (its scalar columns), as
// `export` and `import` (campaigns/data/import.h) write them.
std::string ManifestCsvHeader();
std::string ManifestCsvRow(const nlohmann::json& manifest_line);

// Train / validation / test fractions; a run's split is a function of its seed alone, so
// every run of a seed lands in the same split whatever the shard.
struct SplitSpec {
  bool enabled = false;
  double train = 0.6, validation = 0.2, test = 0.2;
};
// Parses "0.6/0.2/0.2" (fractions summing to 1); errors name --split and the value.
SplitSpec ParseSplit(const std::string& text);
std::string SplitOf(const SplitSpec& split, unsigned long long seed);

constexpr int kDefaultGzipLevel = 1;  // fastest: export costs about what run does (docs/monitor-api.md)
// Throws InputError("--gzip-level", ...) naming a level outside 1..9.
void CheckGzipLevel(int level);

struct ExportOptions {
  std::string output_dir = "export";
  int threads = 0;
  ShardSpec shard;
  SplitSpec split;
  // zlib's level for runs/*.csv.gz, 1 (fastest) to 9 (smallest). 6, the default, is what export
  // has always written (byte for byte); 1 costs about a quarter of its CPU time for files about
  // a fifth larger (docs/monitor-api.md, "Export and score"). The text inside is the same.
  int gzip_level = kDefaultGzipLevel;
  std::function<void(long done, long total)> progress;
};
struct ExportResult {
  long runs = 0;
  long failed = 0;
};
ExportResult ExportCampaign(const Campaign& campaign, const ExportOptions& options);

// Scores the verdicts in `verdicts_path` against the runs of `dir` (an export or a run output
// directory of `campaign`) and writes `output_dir`/{campaign.json, results.jsonl}. Every bad
// line (not JSON, an unknown run_id, a time outside its run, a joint that does not exist, an
// unknown family, a non-finite magnitude) is listed in one InputError naming the file and each
// line (an unknown run_id with the nearest known one); nothing is written then.
struct ScoreResult {
  long runs = 0;
  long verdicts = 0;
  long runs_without_verdicts = 0;
  CampaignSpec campaign;  // the scored campaign (ScoredCampaign), as campaign.json holds it
};
// Reads a verdicts file (JSON Lines, as `armfault score` takes it) from `in`: each line parsed
// strictly (core/base ParseJsonText: a duplicate key or a number beyond a double is an error
// naming its field; a NaN or Infinity, as Python's json.dumps writes them, is explained: "write
// null"), read as a verdict, its run_id looked up by `run_known` (which returns why an id is
// refused, or "" for a run it knows, and may set `*hint`, "did you mean ...?", when `hint` is
// not null), checked against the run (CheckVerdict: `joints`, `duration_s`, the fault
// `families`) and handed to `each` with its run_id. Lines of only white space are skipped.
// Every line is read: when any is bad, one InputError holding each bad line's
// "PATH: line N: [pointer: ]why" (the first kMaxReportedErrors kept, the rest counted as
// unlisted) is thrown at the end. What the fuzzer (tests/fuzz/fuzz_verdicts.cc) drives with
// arbitrary bytes.
struct VerdictLimits {
  int joints = 0;
  double duration_s = 0;
  std::vector<std::string> families;
};
void ReadVerdicts(std::istream& in, const std::string& path, const VerdictLimits& limits,
                  const std::function<std::string(const std::string& run_id, std::string* hint)>& run_known,
                  const std::function<void(const std::string& run_id, const Verdict& verdict)>& each);

// A truth record from a manifest line (the monitor's keys absent) or a results.jsonl line (its
// monitor's outcome dropped): what `score` and `replay` score against. Throws
// std::runtime_error naming a missing or mistyped key.
RunRecord TruthOf(nlohmann::json line);

// `campaign` is DIR's campaign; the scored directory's campaign (ScoredCampaign, returned in
// ScoreResult::campaign) records the verdicts file as its monitor: campaign.json holds it, and
// the summary must be made of it (campaigns/running/run_outputs.h, FinishRunDirectory).
ScoreResult ScoreExternalVerdicts(const CampaignSpec& campaign, const std::string& dir, const std::string& verdicts_path,
                                  const std::string& output_dir);

// `campaign` with its monitor replaced by the verdicts' source, {"type": "verdicts", "file":
// `verdicts_path` as given, "sha256": SHA-256 of the file's bytes}, in `monitor` and in
// `resolved` (so the campaign hash is of the scored campaign: two detectors' verdicts on one
// export are two campaigns to `diff`, and `tune` refuses a detector it cannot re-threshold).
CampaignSpec ScoredCampaign(const CampaignSpec& campaign, const std::string& verdicts_path);

}  // namespace armfault
