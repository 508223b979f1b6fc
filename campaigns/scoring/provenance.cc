#include "campaigns/scoring/provenance.h"

#include <algorithm>
#include <array>
#include <cstdio>

#include <openssl/evp.h>
#include <openssl/sha.h>

#include <fstream>
#include <memory>
#include <vector>

#include "core/base/json_input.h"
#include "campaigns/spec/cases.h"

namespace armfault {

std::string Sha256Hex(std::string_view bytes) {
  unsigned char digest[SHA256_DIGEST_LENGTH];
  SHA256(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), digest);
  std::string hex;
  char buf[3];
  for (unsigned char byte : digest) {
    std::snprintf(buf, sizeof buf, "%02x", byte);
    hex += buf;
  }
  return hex;
}

std::string Sha256FileHex(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot read the file");
  const std::unique_ptr<EVP_MD_CTX, void (*)(EVP_MD_CTX*)> ctx(EVP_MD_CTX_new(), &EVP_MD_CTX_free);
  if (!ctx || EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) != 1) throw std::runtime_error("SHA-256: cannot start a digest");
  std::vector<char> block(1 << 20);
  while (in) {
    in.read(block.data(), static_cast<std::streamsize>(block.size()));
    if (in.gcount() > 0) EVP_DigestUpdate(ctx.get(), block.data(), static_cast<size_t>(in.gcount()));
  }
  if (in.bad()) throw InputError(path, "", "cannot read the file");
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  EVP_DigestFinal_ex(ctx.get(), digest, &length);
  std::string hex;
  char buf[3];
  for (unsigned int k = 0; k < length; ++k) {
    std::snprintf(buf, sizeof buf, "%02x", digest[k]);
    hex += buf;
  }
  return hex;
}

std::string CampaignHash(const nlohmann::json& resolved_campaign) {
  return "sha256:" + Sha256Hex(resolved_campaign.dump());
}

std::optional<std::string> ClaimedCampaignHash(const nlohmann::json& file, const std::string& path) {
  if (!file.is_object()) return std::nullopt;
  std::optional<std::string> stored, embedded;
  if (auto it = file.find("campaign_hash"); it != file.end() && !it->is_null()) {
    if (!it->is_string()) throw InputError(path, "/campaign_hash", "expected a string, got " + Describe(*it));
    stored = it->get<std::string>();
  }
  // Only an object is a resolved campaign (tuning.json's "campaign" is the campaign's name).
  if (auto it = file.find("campaign"); it != file.end() && it->is_object()) embedded = CampaignHash(*it);
  if (stored && embedded && *stored != *embedded) {
    throw InputError(path, "/campaign_hash",
                     *stored + " is not the hash of the file's own \"campaign\" (" + *embedded +
                         "): the file was edited after armfault wrote it; write it again");
  }
  return stored ? stored : embedded;
}

void RequireOneCampaign(const std::vector<CampaignClaim>& claims) {
  auto named = std::find_if(claims.begin(), claims.end(), [](const CampaignClaim& c) { return c.hash.has_value(); });
  if (named == claims.end()) return;  // no file names a campaign: nothing to compare
  const CampaignClaim& ref = *named;
  for (const CampaignClaim& c : claims) {
    if (c.hash == ref.hash) continue;
    const std::string what =
        c.hash ? "belongs to campaign " + *c.hash + ", but " + ref.file + " to campaign " + *ref.hash
               : "carries no campaign_hash (an older armfault wrote it, or it is of another campaign), but " +
                     ref.file + " belongs to campaign " + *ref.hash;
    throw InputError(c.file, "/campaign_hash",
                     what + ": files of different campaigns are not read together" +
                         (c.remedy.empty() ? std::string() : "; " + c.remedy));
  }
}

CaseMatcher::CaseMatcher(const CampaignSpec& campaign, std::optional<RecordedRuns> recorded)
    : campaign_(campaign), count_(CaseCount(campaign)), recorded_(std::move(recorded)) {}

std::string CaseMatcher::Mismatch(const RunRecord& r) const {
  if (recorded_) {
    const auto it = recorded_->run_ids.find(r.case_index);
    if (it == recorded_->run_ids.end()) {
      return "case " + std::to_string(r.case_index) + " (run \"" + r.run_id + "\") is not a case of the " +
             std::to_string(recorded_->run_ids.size()) + " recorded runs of " + recorded_->manifest_path;
    }
    if (it->second != r.run_id) {
      return "case " + std::to_string(r.case_index) + " is run \"" + r.run_id + "\" here but \"" + it->second +
             "\" in " + recorded_->manifest_path;
    }
    return "";
  }
  if (r.case_index < 0 || r.case_index >= count_) {
    return "case " + std::to_string(r.case_index) + " (run \"" + r.run_id + "\") is not one of the campaign's " +
           std::to_string(count_) + " cases";
  }
  const CaseSpec spec = CaseAt(campaign_, r.case_index);
  const std::string& run_id = spec.run_id;
  const uint64_t seed = spec.seed;
  if (run_id != r.run_id) {
    return "case " + std::to_string(r.case_index) + " is run \"" + r.run_id + "\" here but \"" + run_id +
           "\" in the campaign";
  }
  if (seed != r.seed) {
    return "run \"" + r.run_id + "\" has seed " + std::to_string(r.seed) + " here but " + std::to_string(seed) +
           " in the campaign";
  }
  return "";
}

std::string CaseMatcher::NotOf(const std::string& campaign_path, const std::string& dir) const {
  if (recorded_) {
    return ": this results.jsonl is not a replay of the runs of " + recorded_->manifest_path + " (the import " + dir +
           "/replay.json names as the source); replay that import into " + dir + " again";
  }
  return ": this results.jsonl is not a run of " + campaign_path +
         " (files of different campaigns are not read together); run the campaign into " + dir + " again";
}

}  // namespace armfault
