// `armfault export` and `armfault score`: the exported signals are exactly what the monitor saw
// (replaying them through the built-in monitor and scoring its verdicts offline gives the live
// run's diagnosis), the manifest carries the truth, shards and splits are stable, and bad
// verdict files are rejected with their line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "campaigns/spec/campaign.h"
#include "campaigns/data/export.h"
#include "campaigns/scoring/provenance.h"
#include "campaigns/data/replay.h"
#include "campaigns/running/run_dir.h"
#include "campaigns/tuning/tuning.h"
#include "campaigns/running/runner.h"
#include "core/monitors/power_monitor.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing::Not;
using testing_support::ErrorOf;
using testing_support::ScratchDir;

Campaign Small() {
  return CampaignFromJson(json::parse(R"({
    "name": "export", "seed": 11, "duration_s": 4,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": 0.6, "onset_s": 1.0},
               {"family": "friction_increase", "joint": 3, "friction_factor": 2.5, "onset_s": 1.5, "profile": "incipient",
                "ramp_s": 0.5},
               {"family": "kt_degradation", "joint": 1, "kt_factor": 0.6, "onset_s": 1.0}],
    "healthy": 2
  })"),
                          "c.json", ".");
}

std::string Gunzip(const std::string& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  EXPECT_NE(f, nullptr) << path;
  std::string out;
  char buf[65536];
  int n;
  while ((n = gzread(f, buf, sizeof buf)) > 0) out.append(buf, static_cast<size_t>(n));
  gzclose(f);
  return out;
}

std::vector<json> ReadLines(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::vector<json> out;
  std::string line;
  while (std::getline(in, line)) out.push_back(json::parse(line));
  return out;
}

TEST(Export, SignalsReplayedOfflineScoreAsTheLiveRun) {
  const Campaign c = Small();
  ScratchDir dir("export");
  ExportOptions o;
  o.output_dir = (dir.path() / "x").string();
  o.threads = 2;
  const ExportResult r = ExportCampaign(c, o);
  ASSERT_EQ(r.runs, 5);
  EXPECT_EQ(r.failed, 0);
  const std::vector<json> manifest = ReadLines(dir.path() / "x" / "manifest.jsonl");
  ASSERT_EQ(manifest.size(), 5u);
  // The truth, and nothing of the monitor's.
  EXPECT_EQ(manifest[0]["family"], "kt_degradation");
  EXPECT_EQ(manifest[0]["joint"], 3);
  EXPECT_EQ(manifest[0]["onset_s"], 1.0);
  EXPECT_EQ(manifest[0]["magnitude"], 0.6);
  EXPECT_EQ(manifest[0]["profile"], "abrupt");
  EXPECT_EQ(manifest[1]["profile"], "incipient");
  EXPECT_EQ(manifest[2]["excited"], false);  // joint 1 stands still in exp1
  EXPECT_TRUE(manifest[3]["family"].is_null());
  EXPECT_FALSE(manifest[0].contains("detected"));
  EXPECT_FALSE(manifest[0].contains("decision"));
  EXPECT_EQ(manifest[0]["signals"], "runs/000000.csv.gz");
  EXPECT_EQ(manifest[0]["ticks"], 2001);  // 4 s at 500 Hz, both ends
  std::ifstream csv(dir.path() / "x" / "manifest.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_THAT(header, HasSubstr("case,run_id,split,signals,ticks"));

  // Replay every run's exported signals through the built-in monitor, write its verdicts as an
  // offline tool would, and score them: the diagnosis of the live run, field for field.
  const auto& power = dynamic_cast<const PowerEfficiencyModel&>(*c.monitor_model);
  std::ostringstream verdicts;
  const int joints = static_cast<int>(c.robot.modules.size());
  for (const json& m : manifest) {
    std::vector<double> t_s;
    std::vector<std::vector<JointSignals>> ticks;
    // The library's reader (campaigns/data/replay.h), which `armfault replay` streams runs with.
    ReadSignalsCsv((dir.path() / "x" / m["signals"].get<std::string>()).string(), joints,
                   [&](double t, const std::vector<JointSignals>& s) {
                     t_s.push_back(t);
                     ticks.push_back(s);
                   });
    ASSERT_EQ(t_s.size(), m["ticks"].get<size_t>());
    PowerEfficiencyMonitor monitor(power.model());
    for (size_t k = 0; k < t_s.size(); ++k) monitor.Observe(t_s[k], ticks[k]);
    monitor.Finish(t_s.back());
    for (const Verdict& v : monitor.output().verdicts) {
      verdicts << json{{"run_id", m["run_id"]}, {"t_s", v.t_s},           {"joint", v.joint},
                       {"family", v.family},    {"alarm", v.alarm},       {"magnitude", v.magnitude},
                       {"magnitude_name", v.magnitude_name}, {"confidence", v.confidence}, {"state", HealthStateName(v.state)}}
                      .dump()
               << "\n";
    }
  }
  const std::string verdicts_path = dir.Write("verdicts.jsonl", verdicts.str());
  const ScoreResult s = ScoreExternalVerdicts(c, (dir.path() / "x").string(), verdicts_path, (dir.path() / "s").string());
  EXPECT_EQ(s.runs, 5);
  const std::vector<json> scored = ReadLines(dir.path() / "s" / "results.jsonl");
  const std::vector<CaseSpec> cases = ExpandCases(c);
  int detected = 0;
  for (size_t k = 0; k < cases.size(); ++k) {
    const json live = ToJson(RunCase(c, cases[k]));
    for (const char* key : {"run_id", "family", "joint", "onset_s", "excited", "detected", "detection_time_s", "latency_s",
                            "isolated_family", "isolated_joint", "magnitude_name", "magnitude_estimate",
                            "alarm_before_onset", "status", "effect", "variation"}) {
      EXPECT_EQ(scored[k][key], live[key]) << key << " of " << live["run_id"];
    }
    detected += live["detected"].get<bool>();
  }
  EXPECT_GE(detected, 2);  // the comparison is not between two empty diagnoses
}

TEST(Export, ShardsPartitionTheRunsAndTheSplitFollowsTheSeed) {
  const Campaign c = Small();
  ScratchDir dir("export_shards");
  ExportOptions whole;
  whole.output_dir = (dir.path() / "all").string();
  whole.split = ParseSplit("0.5/0.25/0.25");
  ExportCampaign(c, whole);
  std::map<std::string, json> by_id;
  for (const json& m : ReadLines(dir.path() / "all" / "manifest.jsonl")) by_id[m["run_id"]] = m;
  size_t seen = 0;
  for (int k = 0; k < 2; ++k) {
    ExportOptions part = whole;
    part.output_dir = (dir.path() / ("s" + std::to_string(k))).string();
    part.shard = {k, 2};
    ExportCampaign(c, part);
    for (const json& m : ReadLines(dir.path() / ("s" + std::to_string(k)) / "manifest.jsonl")) {
      ++seen;
      EXPECT_EQ(m, by_id.at(m["run_id"]));
      EXPECT_EQ(m["split"], SplitOf(whole.split, m["seed"].get<unsigned long long>()));
      const std::string file = m["signals"];
      EXPECT_EQ(Gunzip((dir.path() / ("s" + std::to_string(k)) / file).string()),
                Gunzip((dir.path() / "all" / file).string()));
    }
  }
  EXPECT_EQ(seen, by_id.size());
  EXPECT_THAT(ErrorOf([] { ParseSplit("0.6/0.2"); }).message(), HasSubstr("got \"0.6/0.2\""));
  EXPECT_THAT(ErrorOf([] { ParseSplit("0.6/0.3/0.2"); }).message(), HasSubstr("summing to 1"));
}

// Export runs no monitor (RunCasePlant); its manifest is still the live run's record, key for
// key, less the monitor's outcome and plus the export's own keys.
TEST(Export, ManifestIsTheLiveRecordsTruthWithoutRunningAMonitor) {
  const Campaign c = Small();
  ScratchDir dir("export_truth");
  ExportOptions o;
  o.output_dir = (dir.path() / "x").string();
  ExportCampaign(c, o);
  const std::vector<json> manifest = ReadLines(dir.path() / "x" / "manifest.jsonl");
  const std::vector<CaseSpec> cases = ExpandCases(c);
  ASSERT_EQ(manifest.size(), cases.size());
  const std::set<std::string> monitor_keys = {"detected",       "detection_time_s", "latency_s",  "isolated_family",
                                              "isolated_joint", "magnitude_name",   "magnitude_estimate",
                                              "confidence",     "alarm_before_onset", "miss_reason", "decision"};
  const std::set<std::string> export_keys = {"split", "signals", "ticks", "end_s", "profile"};
  int excited = 0;
  for (size_t k = 0; k < cases.size(); ++k) {
    const json live = ToJson(RunCase(c, cases[k]));
    for (const auto& [key, value] : live.items()) {
      if (monitor_keys.count(key)) {
        EXPECT_FALSE(manifest[k].contains(key)) << key;
      } else {
        EXPECT_EQ(manifest[k][key], value) << key << " of " << live["run_id"];
      }
    }
    for (const auto& [key, value] : manifest[k].items()) {
      EXPECT_TRUE(live.contains(key) || export_keys.count(key)) << key;
    }
    excited += manifest[k]["excited"] == true;
  }
  EXPECT_GE(excited, 2);  // effects were measured, not left empty
}

// --gzip-level: other bytes, the same text; outside 1..9 an error naming the option.
TEST(Export, GzipLevelChangesTheBytesNotTheText) {
  const Campaign c = Small();
  ScratchDir dir("export_level");
  ExportOptions o;
  EXPECT_EQ(o.gzip_level, 1);  // the default: the fastest
  o.output_dir = (dir.path() / "one").string();
  ExportCampaign(c, o);
  o.output_dir = (dir.path() / "six").string();
  o.gzip_level = 6;
  ExportCampaign(c, o);
  const std::string file = "runs/000000.csv.gz";
  const auto size = [&](const char* d) { return std::filesystem::file_size(dir.path() / d / file); };
  EXPECT_GT(size("one"), size("six"));
  EXPECT_EQ(Gunzip((dir.path() / "one" / file).string()), Gunzip((dir.path() / "six" / file).string()));
  for (int bad : {0, 10}) {
    o.gzip_level = bad;
    const InputError e = ErrorOf([&] { ExportCampaign(c, o); });
    EXPECT_EQ(e.source(), "--gzip-level");
    EXPECT_THAT(e.message(), HasSubstr("got " + std::to_string(bad)));
  }
}

TEST(Score, BadVerdictLinesNameTheLine) {
  const Campaign c = Small();
  ScratchDir dir("score_bad");
  ExportOptions o;
  o.output_dir = (dir.path() / "x").string();
  ExportCampaign(c, o);
  const std::string id = ReadLines(dir.path() / "x" / "manifest.jsonl")[0]["run_id"];
  auto error = [&](const std::string& bad) {
    const std::string good = json{{"run_id", id}, {"t_s", 1.5}, {"joint", 3}, {"family", "kt_degradation"},
                                  {"alarm", true}, {"magnitude", 0.6}}.dump();
    const std::string path = dir.Write("v.jsonl", good + "\n" + bad + "\n");
    // A copy: what() points into the exception, which is gone at the end of this statement.
    return std::string(
        ErrorOf([&] { ScoreExternalVerdicts(c, (dir.path() / "x").string(), path, (dir.path() / "s").string()); }).what());
  };
  EXPECT_THAT(error(R"({"run_id": "nope", "t_s": 1, "joint": 3, "family": "", "alarm": false, "magnitude": 0})"),
              HasSubstr("v.jsonl: line 2: unknown run_id \"nope\""));
  EXPECT_THAT(error(json{{"run_id", id}, {"t_s", 9.0}, {"joint", 3}, {"family", ""}, {"alarm", false}, {"magnitude", 0}}.dump()),
              HasSubstr("line 2: t_s 9 outside the run [0, 4] s"));
  EXPECT_THAT(error(json{{"run_id", id}, {"t_s", 2.0}, {"joint", 3}, {"family", "gremlins"}, {"alarm", true}, {"magnitude", 1}}.dump()),
              HasSubstr("line 2: unknown fault family \"gremlins\""));
  EXPECT_THAT(error(json{{"run_id", id}, {"t_s", 2.0}, {"joint", 0}, {"family", ""}, {"alarm", false}, {"magnitude", 0}}.dump()),
              HasSubstr("line 2: joint 0 out of range, expected 1..3"));
  EXPECT_THAT(error(json{{"run_id", id}, {"t_s", 2.0}, {"joint", 1}, {"family", ""}, {"alarm", "yes"}, {"magnitude", 0}}.dump()),
              HasSubstr("line 2: /alarm: expected true or false"));
  EXPECT_THAT(error("{not json"), HasSubstr("line 2: "));
  // Read strictly (core/base ParseJsonText): a key given twice and a number beyond a double
  // name their field.
  EXPECT_THAT(error("{\"run_id\": \"" + id + "\", \"t_s\": 1, \"t_s\": 2, \"joint\": 3, \"alarm\": false}"),
              HasSubstr("line 2: /t_s: the key \"t_s\" is given twice"));
  EXPECT_THAT(error("{\"run_id\": \"" + id + "\", \"t_s\": 1e999, \"joint\": 3, \"alarm\": false}"),
              HasSubstr("line 2: /t_s: the number 1e999 is beyond the range of a double"));
  EXPECT_THAT(error(json{{"run_id", id}, {"t_s", 2.0}, {"joint", 1}, {"alarm", false}, {"magnitud", 0}}.dump()),
              HasSubstr("line 2: /magnitud"));
  // Nothing written in place of a good output.
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "s" / "results.jsonl"));
}

// Every bad line in one error (the first 20 listed, the rest counted), an unknown run_id with
// the nearest known one, and Python's NaN explained; good lines between bad ones change nothing.
TEST(Score, EveryBadLineIsListedInOneErrorWithHints) {
  const Campaign c = Small();
  ScratchDir dir("score_every_bad");
  ExportOptions o;
  o.output_dir = (dir.path() / "x").string();
  ExportCampaign(c, o);
  const std::string id = ReadLines(dir.path() / "x" / "manifest.jsonl")[0]["run_id"];
  const std::string good = json{{"run_id", id}, {"t_s", 1.5}, {"joint", 3}, {"family", "kt_degradation"},
                                {"alarm", true}, {"magnitude", 0.6}}.dump();
  std::string text = good + "\n";
  // Line 2: a typo in the run_id; 3: Python's NaN; 4: Infinity; 5..29: 25 joints out of range.
  const std::string typo = id + "x";
  text += json{{"run_id", typo}, {"t_s", 1}, {"joint", 3}, {"alarm", false}}.dump() + "\n";
  text += "{\"run_id\": \"" + id + "\", \"t_s\": 1, \"joint\": 3, \"alarm\": false, \"magnitude\": NaN}\n";
  text += "{\"run_id\": \"" + id + "\", \"t_s\": 1, \"joint\": 3, \"alarm\": false, \"confidence\": -Infinity}\n";
  for (int k = 0; k < 25; ++k) {
    text += json{{"run_id", id}, {"t_s", 1}, {"joint", 10 + k}, {"alarm", false}}.dump() + "\n" + good + "\n";
  }
  const std::string path = dir.Write("v.jsonl", text);
  const InputError e =
      ErrorOf([&] { ScoreExternalVerdicts(c, (dir.path() / "x").string(), path, (dir.path() / "s").string()); });
  EXPECT_EQ(e.count(), 28u);  // 3 + 25
  const std::vector<InputError> listed = e.errors();
  ASSERT_EQ(listed.size(), kMaxReportedErrors);
  EXPECT_THAT(listed[0].what(), HasSubstr("v.jsonl: line 2: unknown run_id \"" + typo + "\""));
  EXPECT_EQ(listed[0].hint(), "did you mean \"" + id + "\"?");
  EXPECT_THAT(listed[1].what(), HasSubstr("v.jsonl: line 3: /magnitude: NaN is not JSON; write null (Python's json.dumps"));
  EXPECT_THAT(listed[2].what(), HasSubstr("line 4: /confidence: -Infinity is not JSON; write null or a finite number"));
  EXPECT_THAT(listed[3].what(), HasSubstr("line 5: joint 10 out of range, expected 1..3"));
  EXPECT_THAT(listed[19].what(), HasSubstr("line 37: joint 26 out of range"));
  const std::vector<std::string> lines = ErrorReportLines(e);
  ASSERT_EQ(lines.size(), kMaxReportedErrors + 1);
  EXPECT_EQ(lines.back(), "... and 8 more errors");
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "s" / "results.jsonl"));
  // Not JSON for another reason: the parser's message, no NaN advice ("NaN" in a string is text).
  const std::string other = dir.Write("w.jsonl", "{\"run_id\": \"NaN\", \"t_s\": 1,, }\n");
  const InputError e2 =
      ErrorOf([&] { ScoreExternalVerdicts(c, (dir.path() / "x").string(), other, (dir.path() / "s").string()); });
  EXPECT_THAT(e2.what(), HasSubstr("line 1: not valid JSON"));
  EXPECT_THAT(e2.what(), Not(HasSubstr("write null")));
}

// A score directory's monitor is the verdicts file (as given, with its SHA-256), so its
// campaign hash is its own: another verdicts file is another campaign, the export's campaign
// is not this one, `tune` refuses it and nothing can run it.
TEST(Export, ScoreRecordsTheVerdictsAsItsMonitor) {
  const Campaign c = Small();
  ScratchDir dir("export_score_monitor");
  ExportOptions o;
  o.output_dir = (dir.path() / "x").string();
  ExportCampaign(c, o);
  const std::string id = ReadLines(dir.path() / "x" / "manifest.jsonl")[0]["run_id"];
  const std::string text = json{{"run_id", id}, {"t_s", 1.5}, {"joint", 3}, {"family", "kt_degradation"},
                                {"alarm", true}, {"magnitude", 0.6}}.dump() + "\n";
  const std::string path = dir.Write("v.jsonl", text);
  const ScoreResult r = ScoreExternalVerdicts(c, (dir.path() / "x").string(), path, (dir.path() / "s").string());
  const json monitor = json{{"type", "verdicts"}, {"file", path}, {"sha256", Sha256Hex(text)}};
  EXPECT_EQ(r.campaign.resolved["monitor"], monitor);
  EXPECT_EQ(r.campaign.monitor.type, "verdicts");
  const json written = ReadCampaignFileJson(dir.path() / "s");
  EXPECT_EQ(written["campaign"]["monitor"], monitor);
  // Everything else is the export's campaign; the hash is not.
  json rest = written["campaign"];
  rest["monitor"] = c.resolved["monitor"];
  EXPECT_EQ(rest, c.resolved);
  EXPECT_NE(CampaignHash(written["campaign"]), CampaignHash(c.resolved));
  // Read back as a spec (report, merge, diff do), but never built to run.
  EXPECT_EQ(ReadRunDirCampaign(dir.path() / "s").monitor.settings, (json{{"file", path}, {"sha256", Sha256Hex(text)}}));
  EXPECT_THAT(ErrorOf([&] { CampaignFromJson(written["campaign"], "s/campaign.json", "."); }).what(),
              HasSubstr("scored by armfault score: there is no monitor to run"));
  // Other verdicts (one byte more): another campaign.
  const std::string other = dir.Write("w.jsonl", text + "\n");
  const ScoreResult r2 = ScoreExternalVerdicts(c, (dir.path() / "x").string(), other, (dir.path() / "s2").string());
  EXPECT_NE(CampaignHash(r2.campaign.resolved), CampaignHash(r.campaign.resolved));
  // tune: nothing to re-threshold.
  const InputError e = ErrorOf([&] { TuneCampaignDir((dir.path() / "s").string(), TuneOptions{}); });
  EXPECT_EQ(e.pointer(), "/campaign/monitor/type");
  EXPECT_THAT(e.what(), HasSubstr("verdicts cannot be re-thresholded; tune the detector that wrote them"));
  // A bad hash in a hand-edited campaign.json is named.
  json bad = written["campaign"];
  bad["monitor"]["sha256"] = "abc";
  EXPECT_THAT(ErrorOf([&] { CampaignSpecFromJson(bad, "b.json", "."); }).what(),
              HasSubstr("/monitor/sha256: expected the SHA-256 of the verdicts file as 64 lowercase hex digits"));
}

}  // namespace
}  // namespace armfault
