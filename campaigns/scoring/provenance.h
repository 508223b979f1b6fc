// Which campaign a file belongs to. Every output of a campaign carries the campaign's content
// hash, so that files of different campaigns are never read together: summary.json and
// tuning.json hold it as "campaign_hash", campaign.json embeds the campaign itself, and the
// report shows it. `armfault report` and `armfault tune` refuse (InputError, exit status 2) a
// directory whose files name different campaigns, or whose results.jsonl lines are not the
// cases of its campaign.json.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "campaigns/spec/campaign_spec.h"
#include "campaigns/scoring/run_record.h"

namespace armfault {

// SHA-256 (FIPS 180-4) of `bytes`, as 64 lowercase hex digits.
std::string Sha256Hex(std::string_view bytes);
// SHA-256 of the bytes of the file at `path`, read in 1 MiB blocks (a verdicts file may be
// larger than memory), as 64 lowercase hex digits. InputError naming `path` when it cannot be read.
std::string Sha256FileHex(const std::string& path);

// The campaign's content hash, "sha256:" + 64 hex digits: SHA-256 of the resolved campaign
// JSON (the "campaign" object of campaign.json and summary.json) serialised by nlohmann's
// dump(): compact, keys sorted, numbers in their shortest round-trip form. Reading that JSON
// back from a file gives the same bytes, so every shard of a campaign, the merged directory
// and an unsharded run all carry the same hash.
std::string CampaignHash(const nlohmann::json& resolved_campaign);

// The campaign a JSON output file names: its "campaign_hash", else the hash of the
// "campaign" object it embeds (campaign.json; a summary.json of an older armfault), else
// nullopt. Throws InputError (naming `path`) when it has both and they disagree: the file was
// edited after it was written.
std::optional<std::string> ClaimedCampaignHash(const nlohmann::json& file, const std::string& path);

// One file's claim, for RequireOneCampaign.
struct CampaignClaim {
  std::string file;                 // its path, for the message
  std::optional<std::string> hash;  // nullopt: the file names no campaign
  std::string remedy;               // what to do when this file is the odd one out
};

// Throws InputError (exit status 2) unless every claim names the campaign of the first claim
// that names one (the reference; when none does, there is nothing to compare). The message
// names both files, both hashes and the odd file's remedy; a file without a hash beside a
// reference with one is refused too (an older armfault wrote it, or it belongs to another
// campaign).
void RequireOneCampaign(const std::vector<CampaignClaim>& claims);

// The runs of recorded data whose campaign.json is a stand-in (an import's: its cases are not
// the runs, its manifest.jsonl is the truth, docs/import.md): each run's case and run_id.
struct RecordedRuns {
  std::string manifest_path;              // for messages
  std::map<long, std::string> run_ids;    // by case
};

// Checks that run records are cases of one campaign: the same run_id and seed at their case
// index. Keeps one (run_id, seed) pair per case. With recorded runs (a replay of an import),
// each record's case and run_id must be a line of their manifest instead (seeds are the
// manifest's defaults, not checked).
class CaseMatcher {
 public:
  // Keeps a reference to `campaign`: computes each case from its index (CaseAt), holding none.
  explicit CaseMatcher(const CampaignSpec& campaign, std::optional<RecordedRuns> recorded = std::nullopt);
  // Empty when `r` is case r.case_index of the campaign (or of the recorded runs), else why not
  // (for a message).
  std::string Mismatch(const RunRecord& r) const;
  // The rest of a Mismatch's message for DIR/results.jsonl: what it is not a run of, and the remedy.
  std::string NotOf(const std::string& campaign_path, const std::string& dir) const;

 private:
  const CampaignSpec& campaign_;
  long count_;
  std::optional<RecordedRuns> recorded_;
};

}  // namespace armfault
