// The campaign hash: SHA-256 against the FIPS 180-4 vectors, the same hash in every shard, the
// merged directory, summary.json and tuning.json, another hash for another campaign, and the
// tuner refusing files of another campaign.
#include "campaigns/scoring/provenance.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "campaigns/scoring/campaign_summary.h"
#include "campaigns/running/merge.h"
#include "campaigns/running/runner.h"
#include "campaigns/tuning/tuning.h"
#include "tests/campaigns/campaign_fixtures.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;
using testing_support::ScratchDir;

TEST(Sha256, MatchesTheStandardVectors) {
  EXPECT_EQ(Sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(Sha256Hex(std::string(1000000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, PaddingAtEveryBlockBoundary) {
  // Lengths around 55/56 (the length field no longer fits the block) and 64 (a full block);
  // expected values from coreutils sha256sum.
  const std::vector<std::pair<size_t, std::string>> cases = {
      {55, "d5e285683cd4efc02d021a5c62014694958901005d6f71e89e0989fac77e4072"},
      {56, "04c26261370ee7541549d16dee320c723e3fd14671e66a099afe0a377c16888e"},
      {63, "75220b47218278e656f2013bb8f0c455a25eaf01e86c64924e9d48d89776d6f2"},
      {64, "7ce100971f64e7001e8fe5a51973ecdfe1ced42befe7ee8d5fd6219506b5393c"},
      {65, "9537c5fdf120482f7d58d25e9ed583f52c02b4e304ea814db1633ad565aed7e9"},
      {119, "000b48d4edf0fa7bee3c6236ecd2785baa5db4eeb8bb54341b029e0d9fa5fb0c"},
      {120, "13f05a0b594787f5ecd315edc96141bd3243203d1b7d4f0836f37308b276ba98"}};
  for (const auto& [n, hex] : cases) EXPECT_EQ(Sha256Hex(std::string(n, 'x')), hex) << n;
}

json Small() { return testing_support::SmallCampaign(1.5); }

json ReadJson(const fs::path& p) {
  std::ifstream in(p);
  return json::parse(in);
}

// summary.json as `armfault run` and `armfault merge` write it: from results.jsonl, with the
// resolved campaign of the directory's campaign.json.
json WriteSummary(const fs::path& dir) {
  SummaryBuilder b;
  std::ifstream in(dir / "results.jsonl");
  std::string line;
  while (std::getline(in, line)) b.Add(RunRecordFromJson(json::parse(line)));
  const json s = b.Build(Floors{}, ReadJson(dir / "campaign.json")["campaign"], "test");
  std::ofstream(dir / "summary.json") << s.dump(2) << "\n";
  return s;
}

TEST(CampaignHash, IsTheSameAfterAFileRoundTripAndDiffersForAnotherCampaign) {
  const Campaign c = CampaignFromJson(Small(), "small.json", ".");
  const std::string h = CampaignHash(c.resolved);
  EXPECT_THAT(h, testing::MatchesRegex("sha256:[0-9a-f]{64}"));
  EXPECT_EQ(CampaignHash(json::parse(c.resolved.dump(2))), h);  // as read back from campaign.json
  EXPECT_EQ(CampaignHash(CampaignFromJson(Small(), "small.json", ".").resolved), h);  // deterministic
  json other = Small();
  other["seed"] = 4;
  EXPECT_NE(CampaignHash(CampaignFromJson(other, "small.json", ".").resolved), h);
  other = Small();
  other["monitor"] = {{"significance", 3.5}};
  EXPECT_NE(CampaignHash(CampaignFromJson(other, "small.json", ".").resolved), h);
}

TEST(CampaignHash, ShardsTheMergedDirectoryAndAnUnshardedRunCarryTheSameHash) {
  ScratchDir dir("provenance_shards");
  const Campaign c = CampaignFromJson(Small(), "small.json", ".");
  RunnerOptions o;
  o.output_dir = (dir.path() / "full").string();
  o.threads = 2;
  RunCampaign(c, o);
  std::vector<std::string> shards;
  for (int k = 0; k < 2; ++k) {
    o.output_dir = (dir.path() / ("s" + std::to_string(k))).string();
    o.shard = {k, 2};
    RunCampaign(c, o);
    shards.push_back(o.output_dir);
  }
  const MergeResult merged = MergeShards(shards, (dir.path() / "merged").string());
  EXPECT_EQ(CampaignHash(merged.campaign.resolved), CampaignHash(c.resolved));

  const std::string expected = CampaignHash(c.resolved);
  TuneOptions tune;
  tune.rule.kind = OperatingRule::Kind::kYouden;  // any shard has a point to choose
  tune.threads = 2;
  for (const std::string name : {"full", "s0", "s1", "merged"}) {
    const fs::path d = dir.path() / name;
    const json summary = WriteSummary(d);
    EXPECT_EQ(summary["campaign_hash"], expected) << name;
    EXPECT_EQ(ClaimedCampaignHash(ReadJson(d / "campaign.json"), "campaign.json"), expected) << name;
    EXPECT_EQ(ClaimedCampaignHash(ReadJson(d / "summary.json"), "summary.json"), expected) << name;
    EXPECT_EQ(TuneCampaignDir(d.string(), tune).report["campaign_hash"], expected) << name;
  }
}

TEST(ClaimedCampaignHash, PrefersTheStoredHashAndRefusesOneThatContradictsTheFile) {
  const json campaign = {{"name", "x"}, {"seed", 1}};
  EXPECT_EQ(ClaimedCampaignHash(json{{"campaign", campaign}}, "campaign.json"), CampaignHash(campaign));
  EXPECT_EQ(ClaimedCampaignHash(json{{"campaign_hash", "sha256:ab"}, {"campaign", "x"}}, "tuning.json"), "sha256:ab");
  EXPECT_EQ(ClaimedCampaignHash(json{{"campaign", "x"}}, "tuning.json"), std::nullopt);  // a name, not a campaign
  EXPECT_EQ(ClaimedCampaignHash(json{{"campaign_hash", nullptr}}, "summary.json"), std::nullopt);
  const InputError e = ErrorOf([&] {
    ClaimedCampaignHash(json{{"campaign", campaign}, {"campaign_hash", "sha256:00"}}, "DIR/summary.json");
  });
  EXPECT_THAT(e.what(), HasSubstr("DIR/summary.json: /campaign_hash: sha256:00 is not the hash of the file's own"));
  EXPECT_THAT(ErrorOf([&] { ClaimedCampaignHash(json{{"campaign_hash", 7}}, "t.json"); }).what(),
              HasSubstr("t.json: /campaign_hash: expected a string"));
}

TEST(RequireOneCampaign, NamesBothFilesAndTheRemedy) {
  RequireOneCampaign({{"DIR/campaign.json", "sha256:aa", ""}, {"DIR/summary.json", "sha256:aa", "x"}});
  RequireOneCampaign({{"DIR/campaign.json", std::nullopt, ""}, {"DIR/summary.json", std::nullopt, "x"}});
  InputError e = ErrorOf([] {
    RequireOneCampaign({{"DIR/summary.json", "sha256:aa", ""},
                        {"DIR/tuning.json", "sha256:bb", "run `armfault tune DIR` to tune this campaign again"}});
  });
  EXPECT_EQ(e.source(), "DIR/tuning.json");
  EXPECT_THAT(e.what(), HasSubstr("belongs to campaign sha256:bb, but DIR/summary.json to campaign sha256:aa"));
  EXPECT_THAT(e.what(), HasSubstr("run `armfault tune DIR`"));
  e = ErrorOf([] {
    RequireOneCampaign({{"DIR/summary.json", "sha256:aa", ""}, {"DIR/tuning.json", std::nullopt, "run tune"}});
  });
  EXPECT_THAT(e.what(), HasSubstr("DIR/tuning.json: /campaign_hash: carries no campaign_hash"));
  EXPECT_THAT(e.what(), HasSubstr("DIR/summary.json belongs to campaign sha256:aa"));
  // The reference is the first file that names a campaign.
  e = ErrorOf([] {
    RequireOneCampaign({{"DIR/campaign.json", std::nullopt, "rerun"}, {"DIR/summary.json", "sha256:bb", ""}});
  });
  EXPECT_EQ(e.source(), "DIR/campaign.json");
}

TEST(CaseMatcher, KnowsTheCasesOfItsCampaign) {
  const Campaign c = CampaignFromJson(Small(), "small.json", ".");
  const std::vector<CaseSpec> cases = ExpandCases(c);
  const CaseMatcher m(c);
  RunRecord r;
  r.case_index = 3;
  r.run_id = cases[3].run_id;
  r.seed = cases[3].seed;
  EXPECT_EQ(m.Mismatch(r), "");
  r.seed += 1;
  EXPECT_THAT(m.Mismatch(r), HasSubstr("has seed"));
  r.run_id = cases[4].run_id;
  EXPECT_THAT(m.Mismatch(r), HasSubstr("is run \"" + cases[4].run_id + "\" here but \"" + cases[3].run_id));
  r.case_index = static_cast<long>(cases.size());
  EXPECT_THAT(m.Mismatch(r), HasSubstr("is not one of the campaign's 16 cases"));
}

// A tiny campaign directory to tune: K_T 0.6 on joint 3 and healthy runs.
json Tiny(int seed) {
  return json::parse(R"({"name": "tiny", "seed": )" + std::to_string(seed) + R"(, "duration_s": 2,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": [0.6], "onset_s": 1.0}],
    "healthy": 2, "repetitions": 2})");
}

TEST(TuneProvenance, RefusesASummaryOrResultsOfAnotherCampaign) {
  ScratchDir dir("provenance_tune");
  RunnerOptions o;
  o.threads = 2;
  for (int seed : {1, 2}) {
    o.output_dir = (dir.path() / ("seed" + std::to_string(seed))).string();
    RunCampaign(CampaignFromJson(Tiny(seed), "tiny.json", "."), o);
    WriteSummary(o.output_dir);
  }
  const fs::path a = dir.path() / "seed1", b = dir.path() / "seed2";
  TuneOptions tune;
  tune.rule.kind = OperatingRule::Kind::kYouden;
  tune.threads = 2;
  EXPECT_EQ(TuneCampaignDir(a.string(), tune).report["campaign_hash"],
            CampaignHash(ReadJson(a / "campaign.json")["campaign"]));

  // summary.json of the other campaign.
  fs::copy_file(b / "summary.json", a / "summary.json", fs::copy_options::overwrite_existing);
  InputError e = ErrorOf([&] { TuneCampaignDir(a.string(), tune); });
  EXPECT_EQ(e.source(), (a / "summary.json").string());
  EXPECT_THAT(e.what(), HasSubstr((a / "campaign.json").string()));
  EXPECT_THAT(e.what(), HasSubstr("files of different campaigns are not read together"));
  WriteSummary(a);
  TuneCampaignDir(a.string(), tune);

  // results.jsonl of the other campaign: same run ids, other seeds.
  fs::copy_file(b / "results.jsonl", a / "results.jsonl", fs::copy_options::overwrite_existing);
  fs::remove(a / "summary.json");
  e = ErrorOf([&] { TuneCampaignDir(a.string(), tune); });
  EXPECT_EQ(e.source(), (a / "results.jsonl").string());
  EXPECT_THAT(e.what(), HasSubstr("line 1: run \"exp1/kt_degradation#0/-/j3/r0\" has seed"));
  EXPECT_THAT(e.what(), HasSubstr("is not a run of " + (a / "campaign.json").string()));
}

}  // namespace
}  // namespace armfault
