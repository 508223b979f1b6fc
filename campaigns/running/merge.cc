#include "campaigns/running/merge.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>

#include "campaigns/scoring/run_record.h"
#include "campaigns/running/runner.h"
#include "core/base/json_input.h"
#include "core/base/output_file.h"
#include "core/base/output_file.h"

namespace armfault {

namespace {

namespace fs = std::filesystem;

struct ShardInput {
  fs::path dir;
  std::string campaign_path, results_path, decisions_path;
  nlohmann::json file;  // campaign.json
  int index = 0, count = 1;
  long cases = 0;       // the whole campaign's
  // No decisions.jsonl: an older armfault's shard, whose results lines carry "decision".
  bool inline_decisions = false;
  std::unique_ptr<std::ifstream> in, decisions;
  long line = 0;        // lines read so far (in both files), for messages
};

long LongAt(const nlohmann::json& j, const std::string& pointer, const std::string& source) {
  const nlohmann::json* v = nullptr;
  try {
    v = &j.at(nlohmann::json::json_pointer(pointer));
  } catch (const nlohmann::json::exception&) {
    throw InputError(source, pointer, "missing: is this an armfault run directory's campaign.json?");
  }
  if (!v->is_number_integer()) throw InputError(source, pointer, "expected a whole number, got " + Describe(*v));
  return v->get<long>();
}

// Reads DIR/campaign.json and checks the keys merge relies on.
ShardInput ReadShard(const std::string& dir) {
  ShardInput s;
  s.dir = dir;
  s.campaign_path = (s.dir / run_dir::kCampaign).string();
  s.results_path = (s.dir / run_dir::kResults).string();
  s.decisions_path = (s.dir / run_dir::kDecisions).string();
  s.file = ReadJsonFile(s.campaign_path);
  if (!s.file.is_object()) throw InputError(s.campaign_path, "", "expected the JSON object `armfault run` writes");
  if (!s.file.contains("armfault_version") || !s.file["armfault_version"].is_string()) {
    throw InputError(s.campaign_path, "/armfault_version", "missing or not a string");
  }
  if (!s.file.contains("campaign") || !s.file["campaign"].is_object()) {
    throw InputError(s.campaign_path, "/campaign", "missing or not an object");
  }
  s.index = static_cast<int>(LongAt(s.file, "/shard/index", s.campaign_path));
  s.count = static_cast<int>(LongAt(s.file, "/shard/count", s.campaign_path));
  s.cases = LongAt(s.file, "/cases", s.campaign_path);
  if (s.count < 1 || s.index < 0 || s.index >= s.count) {
    throw InputError(s.campaign_path, "/shard", "shard " + std::to_string(s.index) + " of " + std::to_string(s.count) +
                                                     " does not exist");
  }
  return s;
}

// Where `b`'s campaign first differs from `a`'s, for the message: "/campaign/seed: 4 here, 3 in ...".
void RequireSameCampaign(const ShardInput& a, const ShardInput& b) {
  const nlohmann::json& ca = a.file["campaign"];
  const nlohmann::json& cb = b.file["campaign"];
  if (ca == cb) return;
  const nlohmann::json patch = nlohmann::json::diff(ca, cb);
  const std::string path = patch.empty() ? "" : patch[0].value("path", "");
  const nlohmann::json::json_pointer ptr(path);
  auto describe = [&](const nlohmann::json& c) { return c.contains(ptr) ? Describe(c.at(ptr)) : std::string("absent"); };
  throw InputError(b.campaign_path, "/campaign" + path,
                   "another campaign than in " + a.campaign_path + " (" + describe(cb) + " here, " + describe(ca) +
                       " there): merge only the shards of one campaign");
}

long ShardCases(long cases, int index, int count) { return cases / count + (index < cases % count ? 1 : 0); }

// Complete lines (ending in '\n') and whether a cut line follows them.
std::pair<long, bool> CountLines(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot open the file for reading: has this shard run?");
  long lines = 0;
  char last = '\n';
  char buffer[1 << 16];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    const std::streamsize n = in.gcount();
    for (std::streamsize k = 0; k < n; ++k) lines += buffer[k] == '\n';
    last = buffer[n - 1];
  }
  return {lines, last != '\n'};
}

std::string ResumeHint(const ShardInput& s) {
  return "finish it with `armfault run <campaign file> --shard " + std::to_string(s.index) + "/" +
         std::to_string(s.count) + " -o " + s.dir.string() + " --resume`";
}

// A shard whose decisions.jsonl does not go with its results.jsonl: --resume keeps only the
// prefix both hold (none without decisions.jsonl) and runs the rest again.
std::string DecisionsHint(const ShardInput& s) {
  return "run the shard again with `armfault run <campaign file> --shard " + std::to_string(s.index) + "/" +
         std::to_string(s.count) + " -o " + s.dir.string() + " --resume` (it reruns the runs without decisions)";
}

// Why the shard's decision statistics cannot be merged with its `lines` results, or "".
// Reads only the first results line when decisions.jsonl is absent (an older armfault's shard
// carries them inline there).
std::string DecisionsProblem(ShardInput& s, long lines) {
  const std::string shard = "shard " + std::to_string(s.index) + "/" + std::to_string(s.count);
  if (!fs::exists(s.decisions_path)) {
    if (lines == 0) return "";
    std::ifstream in(s.results_path, std::ios::binary);
    std::string first;
    std::getline(in, first);
    try {
      if (nlohmann::json::parse(first).contains("decision")) {
        s.inline_decisions = true;
        return "";
      }
    } catch (const nlohmann::json::exception&) {
      return "";  // the merge names the bad line itself
    }
    return "line 1: missing: the file does not exist, but " + shard + "'s results.jsonl holds " + std::to_string(lines) +
           " runs (no inline \"decision\" either; was it run with --summary-only?); " + DecisionsHint(s);
  }
  const auto [decisions, cut] = CountLines(s.decisions_path);
  if (decisions < lines) {
    return "line " + std::to_string(decisions + 1) + ": missing: " + std::to_string(decisions) + " lines" +
           (cut ? " and a cut one" : "") + " for the " + std::to_string(lines) + " runs of " + shard +
           "'s results.jsonl; " + DecisionsHint(s);
  }
  if (decisions > lines || cut) {
    return "line " + std::to_string(lines + 1) + ": more lines than the " + std::to_string(lines) + " runs of " + shard +
           "'s results.jsonl: it was not written with them; " + DecisionsHint(s);
  }
  return "";
}

// The campaign's spec for scoring (name, floors, the case count). Only the spec is read: no
// trajectory CSV file (a merge runs where the shard directories are, not necessarily beside
// the campaign file) and no monitor, which play no part in scoring.
CampaignSpec CampaignForScoring(const ShardInput& first) {
  CampaignSpec c;
  try {
    c = CampaignSpecFromJson(first.file["campaign"], first.campaign_path, first.dir.string());
  } catch (const InputError& e) {
    throw e.Edited([&](std::string* source, std::string* pointer, std::string*) {
      *source = first.campaign_path;
      *pointer = "/campaign" + *pointer;
    });
  }
  c.resolved = first.file["campaign"];  // the written JSON stays the one the shards hold
  if (CaseCount(c) != first.cases) {
    throw InputError(first.campaign_path, "/cases",
                     std::to_string(first.cases) + " cases, but the campaign has " + std::to_string(CaseCount(c)));
  }
  return c;
}

std::string List(const std::vector<int>& xs) {
  std::string out;
  for (size_t k = 0; k < xs.size() && k < 10; ++k) out += (k ? ", " : "") + std::to_string(xs[k]);
  if (xs.size() > 10) out += ", ... (" + std::to_string(xs.size()) + " in all)";
  return out;
}

// One campaign, one version (this binary's), one case count and one shard count: else an
// InputError naming the first shard that differs from the first one given.
void RequireOneSplit(const std::vector<ShardInput>& shards) {
  const ShardInput& first = shards[0];
  const std::string version = first.file["armfault_version"];
  if (version != ARMFAULT_VERSION) {
    throw InputError(first.campaign_path, "/armfault_version",
                     "the shards ran with armfault " + version + ", this is armfault " ARMFAULT_VERSION +
                         ": merge with the version that ran them");
  }
  for (const ShardInput& s : shards) {
    if (s.file["armfault_version"] != first.file["armfault_version"]) {
      throw InputError(s.campaign_path, "/armfault_version",
                       "armfault " + s.file["armfault_version"].get<std::string>() + " ran this shard, armfault " +
                           version + " ran " + first.dir.string());
    }
    RequireSameCampaign(first, s);
    if (s.cases != first.cases) {
      throw InputError(s.campaign_path, "/cases", std::to_string(s.cases) + " here, " + std::to_string(first.cases) +
                                                      " in " + first.campaign_path);
    }
    if (s.count != first.count) {
      throw InputError(s.campaign_path, "/shard/count",
                       "this is shard " + std::to_string(s.index) + "/" + std::to_string(s.count) + ", but " +
                           first.dir.string() + " is shard " + std::to_string(first.index) + "/" +
                           std::to_string(first.count) + ": merge shards of one split only");
    }
  }
}

// Checks that the shards given (of one split) are exactly 0 .. N-1, each once, and returns
// where each is: owner[k] is shard k's position in `shards`.
std::vector<int> ShardOwners(const std::vector<ShardInput>& shards) {
  const int n = shards[0].count;
  std::vector<int> owner(static_cast<size_t>(n), -1);
  for (size_t k = 0; k < shards.size(); ++k) {
    const ShardInput& s = shards[k];
    int& o = owner[static_cast<size_t>(s.index)];
    if (o >= 0) {
      throw InputError(s.campaign_path, "/shard/index",
                       "shard " + std::to_string(s.index) + "/" + std::to_string(n) + " is given twice (also " +
                           shards[static_cast<size_t>(o)].dir.string() + "): give each shard once");
    }
    o = static_cast<int>(k);
  }
  std::vector<int> missing;
  for (int k = 0; k < n; ++k) {
    if (owner[static_cast<size_t>(k)] < 0) missing.push_back(k);
  }
  if (!missing.empty()) {
    throw InputError("merge", "",
                     std::string(missing.size() == 1 ? "shard " : "shards ") + List(missing) + " of " +
                         std::to_string(n) + (missing.size() == 1 ? " is" : " are") +
                         " missing: give the output directories of all shards 0.." + std::to_string(n - 1));
  }
  return owner;
}

// Every shard complete, its decisions.jsonl line for line with results.jsonl, before anything
// is written: else an InputError naming the first problem (shards in index order) and how many
// more shards have one. Marks the shards whose decisions are inline (DecisionsProblem).
void RequireComplete(std::vector<ShardInput>& shards, const std::vector<int>& owner) {
  const int n = static_cast<int>(owner.size());
  std::vector<std::string> incomplete;
  std::string first_problem;
  for (int k = 0; k < n; ++k) {
    ShardInput& s = shards[static_cast<size_t>(owner[static_cast<size_t>(k)])];
    const long expected = ShardCases(s.cases, s.index, s.count);
    const auto [lines, cut] = CountLines(s.results_path);
    std::string problem;
    if (lines < expected) {
      problem = "shard " + std::to_string(k) + "/" + std::to_string(n) + " is incomplete: " + std::to_string(lines) +
                " of its " + std::to_string(expected) + " runs, " + std::to_string(expected - lines) + " missing" +
                (cut ? " (the last line is cut)" : "") + "; " + ResumeHint(s);
    } else if (lines > expected || cut) {
      problem = "shard " + std::to_string(k) + "/" + std::to_string(n) + " has " + std::to_string(expected) +
                " runs, but the file holds " + std::to_string(lines) + " lines" + (cut ? " and a cut one" : "") +
                ": it was not written by this shard's run";
    }
    std::string path = s.results_path;
    if (problem.empty()) {
      problem = DecisionsProblem(s, lines);
      path = s.decisions_path;
    }
    if (!problem.empty()) {
      if (first_problem.empty()) first_problem = problem;
      incomplete.push_back(path);
    }
  }
  if (!incomplete.empty()) {
    throw InputError(incomplete[0], "",
                     first_problem + (incomplete.size() > 1 ? " (and " + std::to_string(incomplete.size() - 1) +
                                                                  " more shards with the same problem)"
                                                            : ""));
  }
}

// Opens every shard's results.jsonl and, unless its decisions are inline, its decisions.jsonl
// (2 N files at once).
void OpenShards(std::vector<ShardInput>& shards) {
  const int n = shards[0].count;
  auto open = [&](const std::string& path) {
    auto in = std::make_unique<std::ifstream>(path, std::ios::binary);
    if (!*in) {
      throw InputError(path, "",
                       "cannot open the file for reading (" + std::to_string(2 * n) +
                           " files of " + std::to_string(n) + " shards are open at once: raise the open-file limit, ulimit -n)");
    }
    return in;
  };
  for (ShardInput& s : shards) {
    s.in = open(s.results_path);
    if (!s.inline_decisions && fs::exists(s.decisions_path)) s.decisions = open(s.decisions_path);
  }
}

// The k-way merge's step for case `c`: the next line of its shard `s` (of `n`), which must be
// valid JSON of case c, into `line`, and that run's decisions line into `decision_line`: the
// next of the shard's decisions.jsonl, of the same case and run_id, or an older shard's inline
// decision written out as the runner writes it (the same numbers print the same). Lines are
// returned as read, each ending in '\n'.
void ReadCase(ShardInput& s, long c, int n, std::string* line, std::string* decision_line) {
  std::getline(*s.in, *line);
  ++s.line;
  const std::string where = "line " + std::to_string(s.line) + ": ";
  long found = -1;
  std::string run_id;
  nlohmann::json inline_decision;
  try {
    nlohmann::json j = nlohmann::json::parse(*line);
    found = j.at("case").get<long>();
    run_id = j.at("run_id").get<std::string>();
    if (s.inline_decisions) {
      if (!j.contains("decision")) {
        throw InputError(s.results_path, "",
                         where + "no inline \"decision\", and " + s.decisions_path + " does not exist; " +
                             DecisionsHint(s));
      }
      inline_decision = std::move(j["decision"]);
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(s.results_path, "", where + "not a results line (" + e.what() + ")");
  }
  if (found != c) {
    throw InputError(s.results_path, "", where + "case " + std::to_string(found) + ", expected case " +
                                             std::to_string(c) + " (shard " + std::to_string(s.index) + "/" +
                                             std::to_string(n) + " in case order)");
  }
  if (s.decisions) {
    std::getline(*s.decisions, *decision_line);
    DecisionLine d;
    try {
      d = DecisionLineFromJson(nlohmann::json::parse(*decision_line));
    } catch (const std::exception& e) {
      throw InputError(s.decisions_path, "", where + "not a decisions line (" + e.what() + "); " + DecisionsHint(s));
    }
    if (d.case_index != found || d.run_id != run_id) {
      throw InputError(s.decisions_path, "",
                       where + "case " + std::to_string(d.case_index) + " \"" + d.run_id + "\", but line " +
                           std::to_string(s.line) + " of " + s.results_path + " is case " + std::to_string(found) +
                           " \"" + run_id + "\": decisions.jsonl does not go with results.jsonl; " + DecisionsHint(s));
    }
  } else {
    RunRecord r;
    r.case_index = found;
    r.run_id = run_id;
    r.decision = std::move(inline_decision);
    *decision_line = DecisionLineJson(r).dump();
  }
  *line += '\n';
  *decision_line += '\n';
}

// The merged files in the output directory, written as temporaries and renamed into place.
struct MergedPaths {
  fs::path results, decisions, results_tmp, decisions_tmp;
};
MergedPaths MergedPathsIn(const fs::path& out) {
  return {out / run_dir::kResults, out / run_dir::kDecisions, out / "results.jsonl.tmp", out / "decisions.jsonl.tmp"};
}

// The k-way merge by case: case c is in shard c % N (owner[c % N] in `shards`), and each
// shard's lines ascend, so the next line of shard c % N must be case c (ReadCase). Writes the
// `cases` lines to the temporaries of `paths`; on an error closes and removes both. Returns
// the runs written.
long MergeLines(std::vector<ShardInput>& shards, const std::vector<int>& owner, long cases, const MergedPaths& paths) {
  const int n = static_cast<int>(owner.size());
  std::FILE* merged = OpenForWriting(paths.results_tmp, "wb");
  std::FILE* merged_decisions = nullptr;
  // Each line checked as it goes: a full disk stops the merge with the system's reason.
  auto write = [](std::FILE* f, const std::string& text, const fs::path& path) {
    if (std::fwrite(text.data(), 1, text.size(), f) != text.size()) {
      throw InputError(path.string(), "", std::string("cannot write: ") + std::strerror(errno ? errno : EIO));
    }
  };
  long runs = 0;
  try {
    merged_decisions = OpenForWriting(paths.decisions_tmp, "wb");
    std::string line, decision_line;
    for (long c = 0; c < cases; ++c) {
      ReadCase(shards[static_cast<size_t>(owner[static_cast<size_t>(c % n)])], c, n, &line, &decision_line);
      write(merged_decisions, decision_line, paths.decisions_tmp);
      write(merged, line, paths.results_tmp);
      ++runs;
    }
    const bool decisions_closed = std::fclose(merged_decisions) == 0;
    merged_decisions = nullptr;
    if (!decisions_closed) throw InputError(paths.decisions_tmp.string(), "", "error while writing");
    const bool results_closed = std::fclose(merged) == 0;
    merged = nullptr;
    if (!results_closed) throw InputError(paths.results_tmp.string(), "", "error while writing");
  } catch (...) {
    if (merged) std::fclose(merged);
    if (merged_decisions) std::fclose(merged_decisions);
    std::error_code ec;
    fs::remove(paths.results_tmp, ec);
    fs::remove(paths.decisions_tmp, ec);
    throw;
  }
  return runs;
}

}  // namespace

MergeResult MergeShards(const std::vector<std::string>& input_dirs, const std::string& output_dir) {
  if (input_dirs.empty()) throw InputError("merge", "", "no shard directories given");
  std::vector<ShardInput> shards;
  shards.reserve(input_dirs.size());
  for (const std::string& dir : input_dirs) shards.push_back(ReadShard(dir));
  RequireOneSplit(shards);
  const std::vector<int> owner = ShardOwners(shards);
  RequireComplete(shards, owner);

  MergeResult result;
  result.campaign = CampaignForScoring(shards[0]);
  result.shards = shards[0].count;

  const fs::path out(output_dir);
  fs::create_directories(out);
  for (const ShardInput& s : shards) {
    if (fs::equivalent(out, s.dir)) {
      throw InputError(output_dir, "", "the output directory is one of the shards: choose another one");
    }
  }
  OpenShards(shards);
  const MergedPaths paths = MergedPathsIn(out);
  result.runs = MergeLines(shards, owner, shards[0].cases, paths);
  // As an unsharded run writes it (the same function, shard 0/1).
  WriteAtomically(out / run_dir::kCampaign, CampaignFileJson(result.campaign, ShardSpec{}).dump(2) + "\n");
  RenameChecked(paths.decisions_tmp, paths.decisions);
  RenameChecked(paths.results_tmp, paths.results);
  return result;
}

}  // namespace armfault
