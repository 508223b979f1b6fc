#include "campaigns/provenance.h"

#include <algorithm>
#include <array>
#include <cstdio>

#include "core/json_input.h"

namespace armfault {

namespace {

constexpr std::array<uint32_t, 64> kRoundConstants = {
    0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5,
    0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174,
    0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
    0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967,
    0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85,
    0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
    0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
    0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2};

uint32_t Rotr(uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }

// One 64-byte block into the state.
void Compress(const unsigned char* block, std::array<uint32_t, 8>* state) {
  uint32_t w[64];
  for (int i = 0; i < 16; ++i) {
    w[i] = static_cast<uint32_t>(block[4 * i]) << 24 | static_cast<uint32_t>(block[4 * i + 1]) << 16 |
           static_cast<uint32_t>(block[4 * i + 2]) << 8 | static_cast<uint32_t>(block[4 * i + 3]);
  }
  for (int i = 16; i < 64; ++i) {
    const uint32_t s0 = Rotr(w[i - 15], 7) ^ Rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
    const uint32_t s1 = Rotr(w[i - 2], 17) ^ Rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
    w[i] = w[i - 16] + s0 + w[i - 7] + s1;
  }
  uint32_t a = (*state)[0], b = (*state)[1], c = (*state)[2], d = (*state)[3];
  uint32_t e = (*state)[4], f = (*state)[5], g = (*state)[6], h = (*state)[7];
  for (int i = 0; i < 64; ++i) {
    const uint32_t t1 = h + (Rotr(e, 6) ^ Rotr(e, 11) ^ Rotr(e, 25)) + ((e & f) ^ (~e & g)) + kRoundConstants[i] + w[i];
    const uint32_t t2 = (Rotr(a, 2) ^ Rotr(a, 13) ^ Rotr(a, 22)) + ((a & b) ^ (a & c) ^ (b & c));
    h = g;
    g = f;
    f = e;
    e = d + t1;
    d = c;
    c = b;
    b = a;
    a = t1 + t2;
  }
  (*state)[0] += a, (*state)[1] += b, (*state)[2] += c, (*state)[3] += d;
  (*state)[4] += e, (*state)[5] += f, (*state)[6] += g, (*state)[7] += h;
}

}  // namespace

std::string Sha256Hex(std::string_view bytes) {
  std::array<uint32_t, 8> state = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                                   0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  const size_t n = bytes.size();
  size_t done = 0;
  for (; done + 64 <= n; done += 64) Compress(data + done, &state);
  // The tail, the 0x80 marker, zeros and the bit length (big-endian) fill one or two blocks.
  unsigned char tail[128] = {};
  const size_t rest = n - done;
  for (size_t i = 0; i < rest; ++i) tail[i] = data[done + i];
  tail[rest] = 0x80;
  const size_t blocks = rest + 1 + 8 <= 64 ? 1 : 2;
  const uint64_t bits = static_cast<uint64_t>(n) * 8;
  for (int i = 0; i < 8; ++i) tail[blocks * 64 - 1 - i] = static_cast<unsigned char>(bits >> (8 * i));
  for (size_t b = 0; b < blocks; ++b) Compress(tail + 64 * b, &state);
  std::string hex;
  char buf[9];
  for (uint32_t word : state) {
    std::snprintf(buf, sizeof buf, "%08x", word);
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

CaseMatcher::CaseMatcher(const Campaign& campaign) {
  for (const CaseSpec& spec : ExpandCases(campaign)) cases_.emplace_back(spec.run_id, spec.seed);
}

std::string CaseMatcher::Mismatch(const RunRecord& r) const {
  if (r.case_index < 0 || r.case_index >= static_cast<long>(cases_.size())) {
    return "case " + std::to_string(r.case_index) + " (run \"" + r.run_id + "\") is not one of the campaign's " +
           std::to_string(cases_.size()) + " cases";
  }
  const auto& [run_id, seed] = cases_[static_cast<size_t>(r.case_index)];
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

}  // namespace armfault
