// Campaign results beyond one uninterrupted process: shards merged into the bytes of an
// unsharded run (and refused when they do not make one campaign), one case re-run alone with
// the same record, and a diverging run recorded as failed while the others complete.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "campaigns/spec/campaign.h"
#include "campaigns/running/merge.h"
#include "campaigns/running/runner.h"
#include "tests/campaigns/campaign_fixtures.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;
using testing_support::Lines;
using testing_support::ReadAll;
using testing_support::ScratchDir;

json Small() { return testing_support::SmallCampaign(1.5); }

Campaign Parse(const json& j) { return CampaignFromJson(j, "c.json", "."); }

// An output directory a refused merge must leave without results: no results.jsonl or
// decisions.jsonl, and no temporary file of either.
struct ScratchOutput {
  std::string dir;
  void ExpectEmpty() const {
    for (const char* name : {"results.jsonl", "decisions.jsonl", "results.jsonl.tmp", "decisions.jsonl.tmp"}) {
      EXPECT_FALSE(fs::exists(fs::path(dir) / name)) << name;
    }
  }
};

// Runs `c` unsharded into DIR/full and as shards 0/3, 1/3, 2/3 into DIR/s0 ... DIR/s2.
class CampaignMerge : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() / ("merge_" + std::to_string(getpid())));
    fs::create_directories(*dir_);
    const Campaign c = Parse(Small());
    RunnerOptions o;
    o.output_dir = Dir("full");
    o.threads = 1;
    RunCampaign(c, o);
    for (int k = 0; k < 3; ++k) {
      o.output_dir = Dir("s" + std::to_string(k));
      o.threads = 2;
      o.shard = {k, 3};
      RunCampaign(c, o);
    }
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
    dir_ = nullptr;
  }
  static std::string Dir(const std::string& name) { return (*dir_ / name).string(); }
  // A copy of shard k to edit.
  static std::string CopyShard(int k, const std::string& name) {
    fs::copy(Dir("s" + std::to_string(k)), Dir(name), fs::copy_options::recursive | fs::copy_options::overwrite_existing);
    return Dir(name);
  }

  static fs::path* dir_;  // shared by the tests: the runs are made once
};
fs::path* CampaignMerge::dir_ = nullptr;

TEST_F(CampaignMerge, ShardsMergeToTheBytesOfAnUnshardedRun) {
  // Any order of the inputs.
  const MergeResult r = MergeShards({Dir("s2"), Dir("s0"), Dir("s1")}, Dir("merged"));
  EXPECT_EQ(r.shards, 3);
  EXPECT_EQ(r.runs, 16);
  EXPECT_EQ(r.campaign.name, "small");
  ASSERT_TRUE(r.campaign.floors.overall.detection_rate.has_value());
  const std::string full = ReadAll(fs::path(Dir("full")) / "results.jsonl");
  EXPECT_EQ(std::count(full.begin(), full.end(), '\n'), 16);
  EXPECT_EQ(ReadAll(fs::path(Dir("merged")) / "results.jsonl"), full);
  EXPECT_EQ(ReadAll(fs::path(Dir("merged")) / "campaign.json"), ReadAll(fs::path(Dir("full")) / "campaign.json"));
  const std::string decisions = ReadAll(fs::path(Dir("full")) / "decisions.jsonl");
  EXPECT_EQ(std::count(decisions.begin(), decisions.end(), '\n'), 16);
  EXPECT_EQ(ReadAll(fs::path(Dir("merged")) / "decisions.jsonl"), decisions);
  EXPECT_FALSE(fs::exists(fs::path(Dir("merged")) / "results.jsonl.tmp"));
  EXPECT_FALSE(fs::exists(fs::path(Dir("merged")) / "decisions.jsonl.tmp"));
}

// An older armfault's layout: each results line with its "decision" inline (the keys sorted,
// as ToJson wrote them), no decisions.jsonl. Returns the new results.jsonl text.
std::string Inline(const fs::path& dir) {
  const std::vector<std::string> results = Lines(ReadAll(dir / "results.jsonl"));
  const std::vector<std::string> decisions = Lines(ReadAll(dir / "decisions.jsonl"));
  std::string text;
  for (size_t k = 0; k < results.size(); ++k) {
    json line = json::parse(results[k]);
    line["decision"] = json::parse(decisions.at(k))["decision"];
    text += line.dump() + "\n";
  }
  std::ofstream(dir / "results.jsonl", std::ios::binary | std::ios::trunc) << text;
  fs::remove(dir / "decisions.jsonl");
  return text;
}

TEST_F(CampaignMerge, ShardsOfAnOlderArmfaultWithInlineDecisionsStillMerge) {
  // Every shard old: results.jsonl copied as it is, the decisions written out as a run does.
  std::vector<std::string> dirs;
  for (int k = 0; k < 3; ++k) {
    dirs.push_back(CopyShard(k, "old" + std::to_string(k)));
    Inline(dirs.back());
  }
  MergeShards(dirs, Dir("merged_old"));
  const std::string full_decisions = ReadAll(fs::path(Dir("full")) / "decisions.jsonl");
  EXPECT_EQ(ReadAll(fs::path(Dir("merged_old")) / "decisions.jsonl"), full_decisions);
  fs::copy(Dir("full"), Dir("full_old"), fs::copy_options::recursive);
  EXPECT_EQ(ReadAll(fs::path(Dir("merged_old")) / "results.jsonl"), Inline(Dir("full_old")));

  // One old shard among new ones.
  MergeShards({dirs[0], Dir("s1"), Dir("s2")}, Dir("merged_mixed"));
  EXPECT_EQ(ReadAll(fs::path(Dir("merged_mixed")) / "decisions.jsonl"), full_decisions);
}

TEST_F(CampaignMerge, ADecisionsFileThatDoesNotGoWithItsResultsIsRefused) {
  // Shard 1 holds cases 1, 4, 7, 10, 13. Its decision lines 2 and 3 swapped.
  const std::string swapped = CopyShard(1, "dswapped");
  const fs::path decisions = fs::path(swapped) / "decisions.jsonl";
  std::vector<std::string> lines = Lines(ReadAll(decisions));
  std::swap(lines[1], lines[2]);
  {
    std::ofstream out(decisions, std::ios::binary | std::ios::trunc);
    for (const std::string& l : lines) out << l << "\n";
  }
  const ScratchOutput none{Dir("m_dswapped")};
  InputError e = ErrorOf([&] { MergeShards({Dir("s0"), swapped, Dir("s2")}, none.dir); });
  EXPECT_EQ(e.source(), decisions.string());
  EXPECT_THAT(e.message(), HasSubstr("line 2: case 7 \"exp1/kt_degradation#0/kt_factor=0.6/j3/r1\", but line 2 of " +
                                     (fs::path(swapped) / "results.jsonl").string() +
                                     " is case 4 \"exp1/kt_degradation#0/kt_factor=0.6/j2/r0\": decisions.jsonl does "
                                     "not go with results.jsonl"));
  EXPECT_THAT(e.message(), HasSubstr("--shard 1/3 -o " + swapped + " --resume"));
  none.ExpectEmpty();

  // Cut after 3 lines and part of the fourth (killed between its two writes and not resumed).
  const std::string cut = CopyShard(1, "dcut");
  const std::string text = ReadAll(fs::path(cut) / "decisions.jsonl");
  size_t pos = 0;
  for (int k = 0; k < 3; ++k) pos = text.find('\n', pos) + 1;
  std::ofstream(fs::path(cut) / "decisions.jsonl", std::ios::binary | std::ios::trunc) << text.substr(0, pos + 50);
  e = ErrorOf([&] { MergeShards({Dir("s0"), cut, Dir("s2")}, none.dir); });
  EXPECT_EQ(e.source(), (fs::path(cut) / "decisions.jsonl").string());
  EXPECT_THAT(e.message(), HasSubstr("line 4: missing: 3 lines and a cut one for the 5 runs of shard 1/3's results.jsonl"));
  none.ExpectEmpty();

  // One line too many.
  const std::string more = CopyShard(2, "dmore");
  std::ofstream(fs::path(more) / "decisions.jsonl", std::ios::binary | std::ios::app)
      << Lines(ReadAll(fs::path(more) / "decisions.jsonl")).back() << "\n";
  e = ErrorOf([&] { MergeShards({Dir("s0"), Dir("s1"), more}, none.dir); });
  EXPECT_EQ(e.source(), (fs::path(more) / "decisions.jsonl").string());
  EXPECT_THAT(e.message(), HasSubstr("line 6: more lines than the 5 runs of shard 2/3's results.jsonl"));
  none.ExpectEmpty();

  // Missing, while results.jsonl carries no decisions either (--summary-only removed them).
  const std::string gone = CopyShard(0, "dgone");
  fs::remove(fs::path(gone) / "decisions.jsonl");
  e = ErrorOf([&] { MergeShards({gone, Dir("s1"), Dir("s2")}, none.dir); });
  EXPECT_EQ(e.source(), (fs::path(gone) / "decisions.jsonl").string());
  EXPECT_THAT(e.message(), HasSubstr("line 1: missing: the file does not exist, but shard 0/3's results.jsonl holds 6 runs"));
  none.ExpectEmpty();

  // An older shard whose later line lost its inline decision: found while merging, and
  // nothing is left behind.
  const std::string old = CopyShard(0, "dold");
  Inline(old);
  std::vector<std::string> old_lines = Lines(ReadAll(fs::path(old) / "results.jsonl"));
  json third = json::parse(old_lines[2]);
  third.erase("decision");
  old_lines[2] = third.dump();
  {
    std::ofstream out(fs::path(old) / "results.jsonl", std::ios::binary | std::ios::trunc);
    for (const std::string& l : old_lines) out << l << "\n";
  }
  e = ErrorOf([&] { MergeShards({old, Dir("s1"), Dir("s2")}, none.dir); });
  EXPECT_EQ(e.source(), (fs::path(old) / "results.jsonl").string());
  EXPECT_THAT(e.message(), HasSubstr("line 3: no inline \"decision\", and " + (fs::path(old) / "decisions.jsonl").string() +
                                     " does not exist"));
  none.ExpectEmpty();
}

TEST_F(CampaignMerge, LinesAreCopiedVerbatimWithKeysMergeDoesNotKnow) {
  // Every line gains a key (as a newer runner might write); merge copies it through.
  std::vector<std::string> dirs;
  for (int k = 0; k < 3; ++k) {
    dirs.push_back(CopyShard(k, "extra" + std::to_string(k)));
    std::string edited;
    for (const std::string& line : Lines(ReadAll(fs::path(dirs.back()) / "results.jsonl"))) {
      edited += line.substr(0, line.size() - 1) + ",\"zz_new\":{\"x\":[1,2.50]}}\n";
    }
    std::ofstream(fs::path(dirs.back()) / "results.jsonl", std::ios::binary | std::ios::trunc) << edited;
  }
  MergeShards(dirs, Dir("merged_extra"));
  std::string expected;
  for (const std::string& line : Lines(ReadAll(fs::path(Dir("full")) / "results.jsonl"))) {
    expected += line.substr(0, line.size() - 1) + ",\"zz_new\":{\"x\":[1,2.50]}}\n";
  }
  EXPECT_EQ(ReadAll(fs::path(Dir("merged_extra")) / "results.jsonl"), expected);
}

TEST_F(CampaignMerge, AMissingOrRepeatedShardIsRefused) {
  const InputError missing = ErrorOf([&] { MergeShards({Dir("s0"), Dir("s2")}, Dir("m_missing")); });
  EXPECT_EQ(missing.message(),
            "shard 1 of 3 is missing: give the output directories of all shards 0..2");
  EXPECT_FALSE(fs::exists(fs::path(Dir("m_missing")) / "results.jsonl"));

  const InputError twice = ErrorOf([&] { MergeShards({Dir("s0"), Dir("s1"), CopyShard(1, "s1_copy"), Dir("s2")}, Dir("m_twice")); });
  EXPECT_EQ(twice.source(), (fs::path(Dir("s1_copy")) / "campaign.json").string());
  EXPECT_EQ(twice.pointer(), "/shard/index");
  EXPECT_THAT(twice.message(), HasSubstr("shard 1/3 is given twice (also " + Dir("s1") + ")"));

  // A shard of another split (0 of 2 in a 3-way merge).
  const std::string other = CopyShard(0, "split2");
  json file = json::parse(ReadAll(fs::path(other) / "campaign.json"));
  file["shard"]["count"] = 2;
  std::ofstream(fs::path(other) / "campaign.json", std::ios::trunc) << file.dump(2) << "\n";
  const InputError split = ErrorOf([&] { MergeShards({Dir("s0"), Dir("s1"), other}, Dir("m_split")); });
  EXPECT_EQ(split.pointer(), "/shard/count");
  EXPECT_THAT(split.message(), HasSubstr("this is shard 0/2, but " + Dir("s0") + " is shard 0/3"));
}

TEST_F(CampaignMerge, ShardsOfDifferentCampaignsAreRefused) {
  const std::string other = CopyShard(1, "other_seed");
  json file = json::parse(ReadAll(fs::path(other) / "campaign.json"));
  file["campaign"]["seed"] = 4;
  std::ofstream(fs::path(other) / "campaign.json", std::ios::trunc) << file.dump(2) << "\n";
  const InputError e = ErrorOf([&] { MergeShards({Dir("s0"), other, Dir("s2")}, Dir("m_other")); });
  EXPECT_EQ(e.source(), (fs::path(other) / "campaign.json").string());
  EXPECT_EQ(e.pointer(), "/campaign/seed");
  EXPECT_THAT(e.message(), HasSubstr("another campaign than in " + (fs::path(Dir("s0")) / "campaign.json").string() +
                                     " (4 here, 3 there)"));
  EXPECT_FALSE(fs::exists(fs::path(Dir("m_other")) / "results.jsonl"));
}

TEST_F(CampaignMerge, AnIncompleteShardIsRefusedWithTheResumeCommand) {
  // Shard 1 holds cases 1, 4, 7, 10, 13: keep 3 lines and half of the fourth (killed).
  const std::string cut = CopyShard(1, "cut");
  const std::string text = ReadAll(fs::path(cut) / "results.jsonl");
  size_t pos = 0;
  for (int k = 0; k < 3; ++k) pos = text.find('\n', pos) + 1;
  std::ofstream(fs::path(cut) / "results.jsonl", std::ios::binary | std::ios::trunc) << text.substr(0, pos + 30);
  const InputError e = ErrorOf([&] { MergeShards({Dir("s0"), cut, Dir("s2")}, Dir("m_cut")); });
  EXPECT_EQ(e.source(), (fs::path(cut) / "results.jsonl").string());
  EXPECT_EQ(e.message(), "shard 1/3 is incomplete: 3 of its 5 runs, 2 missing (the last line is cut); finish it with "
                         "`armfault run <campaign file> --shard 1/3 -o " + cut + " --resume`");
  EXPECT_FALSE(fs::exists(fs::path(Dir("m_cut")) / "results.jsonl"));

  // A shard that never wrote results.
  const std::string none = CopyShard(2, "none");
  fs::remove(fs::path(none) / "results.jsonl");
  const InputError e2 = ErrorOf([&] { MergeShards({Dir("s0"), Dir("s1"), none}, Dir("m_none")); });
  EXPECT_EQ(e2.source(), (fs::path(none) / "results.jsonl").string());
  EXPECT_THAT(e2.message(), HasSubstr("cannot open"));
}

TEST_F(CampaignMerge, LinesOutOfCaseOrderAreRefusedAndNothingIsLeftBehind) {
  const std::string swapped = CopyShard(0, "swapped");
  std::vector<std::string> lines = Lines(ReadAll(fs::path(swapped) / "results.jsonl"));
  std::swap(lines[1], lines[2]);
  std::ofstream out(fs::path(swapped) / "results.jsonl", std::ios::binary | std::ios::trunc);
  for (const std::string& l : lines) out << l << "\n";
  out.close();
  const InputError e = ErrorOf([&] { MergeShards({swapped, Dir("s1"), Dir("s2")}, Dir("m_swapped")); });
  EXPECT_EQ(e.message(), "line 2: case 6, expected case 3 (shard 0/3 in case order)");
  EXPECT_FALSE(fs::exists(fs::path(Dir("m_swapped")) / "results.jsonl"));
  EXPECT_FALSE(fs::exists(fs::path(Dir("m_swapped")) / "results.jsonl.tmp"));

  // The output directory may not be a shard's own.
  const InputError into = ErrorOf([&] { MergeShards({Dir("s0"), Dir("s1"), Dir("s2")}, Dir("s1")); });
  EXPECT_THAT(into.message(), HasSubstr("the output directory is one of the shards"));
}

TEST_F(CampaignMerge, ACaseRunAloneGivesItsResultsLine) {
  // What `armfault trace CAMPAIGN --run ID` relies on: RunCase with an observer attached is the
  // campaign's run, to the byte of its results.jsonl line.
  const Campaign c = Parse(Small());
  const std::vector<std::string> lines = Lines(ReadAll(fs::path(Dir("full")) / "results.jsonl"));
  const std::vector<CaseSpec> cases = ExpandCases(c);
  ASSERT_EQ(lines.size(), cases.size());
  for (const size_t k : {size_t{0}, size_t{9}, cases.size() - 1}) {  // kt, friction (uniform onset), healthy
    long ticks = 0;
    const RunRecord r = RunCase(c, cases[k], [&](const Tick&) { ++ticks; });
    EXPECT_EQ(ToJson(r).dump(), lines[k]) << cases[k].run_id;
    EXPECT_EQ(ticks, 751);  // 500 Hz over 1.5 s, both ends
  }
}

TEST(CampaignMergeShards, MoreShardsThanRunsGiveEmptyValidShardsThatMerge) {
  json j = Small();
  j["faults"] = json::array();
  j["healthy"] = 2;
  j["repetitions"] = 1;
  const Campaign c = Parse(j);
  ASSERT_EQ(CaseCount(c), 2);
  const fs::path dir = fs::temp_directory_path() / ("merge_empty_" + std::to_string(getpid()));
  std::vector<std::string> shards;
  for (int k = 0; k < 4; ++k) {
    RunnerOptions o;
    o.output_dir = (dir / ("s" + std::to_string(k))).string();
    o.shard = {k, 4};
    const RunnerResult r = RunCampaign(c, o);
    EXPECT_EQ(r.total, k < 2 ? 1 : 0);
    shards.push_back(o.output_dir);
  }
  EXPECT_EQ(ReadAll(dir / "s3" / "results.jsonl"), "");  // empty, and there
  EXPECT_TRUE(fs::exists(dir / "s3" / "decisions.jsonl"));
  const MergeResult m = MergeShards(shards, (dir / "merged").string());
  EXPECT_EQ(m.shards, 4);
  EXPECT_EQ(m.runs, 2);
  RunnerOptions whole;
  whole.output_dir = (dir / "full").string();
  RunCampaign(c, whole);
  EXPECT_EQ(ReadAll(dir / "merged" / "results.jsonl"), ReadAll(dir / "full" / "results.jsonl"));
  std::error_code ec;
  fs::remove_all(dir, ec);
}

TEST(CampaignMergeFiles, TrajectoryFilesAreNotNeededToMerge) {
  // A csv trajectory is read relative to the campaign file; merge runs elsewhere, after the
  // shards, and must not need it.
  ScratchDir dir("merge_csv");
  fs::create_directories(dir.path() / "campaign");
  dir.Write("campaign/ramp.csv", "time_s,angle_deg\n0,0\n0.2,5\n0.4,0\n");
  const Campaign c = CampaignFromJson(json::parse(R"({
    "name": "csv", "duration_s": 0.4, "healthy": 3,
    "trajectories": [{"name": "ramp", "joints": {"3": {"type": "csv", "path": "ramp.csv"}}}]
  })"), "csv.json", (dir.path() / "campaign").string());
  RunnerOptions o;
  o.output_dir = (dir.path() / "full").string();
  RunCampaign(c, o);
  std::vector<std::string> shards;
  for (int k = 0; k < 2; ++k) {
    o.output_dir = (dir.path() / ("s" + std::to_string(k))).string();
    o.shard = {k, 2};
    RunCampaign(c, o);
    shards.push_back(o.output_dir);
  }
  fs::remove(dir.path() / "campaign" / "ramp.csv");
  MergeShards(shards, (dir.path() / "merged").string());
  // Two shards, merged: both files are the unsharded run's, byte for byte.
  for (const char* f : {"campaign.json", "results.jsonl", "decisions.jsonl"}) {
    EXPECT_EQ(ReadAll(dir.path() / "merged" / f), ReadAll(dir.path() / "full" / f)) << f;
  }
}

// A robot whose joint-1 viscous friction is applied explicitly at 1 kHz: stable as built,
// numerically unstable (the friction torque overshoots every step) once a fault multiplies
// it by 100, so that run diverges from its own input, without any hook in the code.
json Diverging() {
  return json::parse(R"({
    "name": "diverge", "seed": 5, "duration_s": 1.5,
    "robot": {"modules": [{"friction": {"viscous_Nm_s_per_rad": 0.2}}], "links": [{}]},
    "trajectories": [{"name": "swing", "joints": {"1": {"type": "sine_pair", "amplitude_deg": 20, "omega_rad_s": 2}}}],
    "faults": [{"family": "friction_increase", "joint": 1, "friction_factor": [2, 100], "onset_s": 0.5}],
    "healthy": 2
  })");
}

TEST(CampaignDivergence, ADivergingRunIsAFailedRecordAndTheOthersComplete) {
  ScratchDir dir("diverge");
  const Campaign c = Parse(Diverging());
  RunnerOptions o;
  o.output_dir = dir.path().string();
  o.threads = 2;
  const RunnerResult result = RunCampaign(c, o);
  EXPECT_EQ(result.ran, 4);
  EXPECT_EQ(result.failed, 1);
  const std::vector<std::string> lines = Lines(ReadAll(dir.path() / "results.jsonl"));
  ASSERT_EQ(lines.size(), 4u);
  for (size_t k = 0; k < lines.size(); ++k) {
    const RunRecord r = RunRecordFromJson(json::parse(lines[k]));
    EXPECT_EQ(r.case_index, static_cast<long>(k));
    if (r.run_id == "swing/friction_increase#0/friction_factor=100/j1/r0") {
      EXPECT_FALSE(r.ok);
      EXPECT_THAT(r.failure_reason, HasSubstr("simulation diverged at t="));
      EXPECT_THAT(r.failure_reason, HasSubstr("joint 1 velocity"));
      EXPECT_EQ(json::parse(lines[k])["status"], "failed");
    } else {
      EXPECT_TRUE(r.ok) << r.run_id << ": " << r.failure_reason;
      EXPECT_EQ(json::parse(lines[k])["reason"], nullptr);
    }
  }
}

}  // namespace
}  // namespace armfault
