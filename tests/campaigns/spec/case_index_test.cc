// Case k of a campaign from the campaign and k alone (CaseAt): the same cases, byte for byte,
// as the shipped campaigns have always expanded to, and in the same order.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "campaigns/spec/campaign.h"

namespace armfault {
namespace {

// FNV-1a over every case's run_id, seed, group, fault and variation, in case order.
uint64_t CasesDigest(const Campaign& c) {
  uint64_t h = 1469598103934665603ULL;
  auto add = [&](const std::string& s) {
    for (unsigned char ch : s) h = (h ^ ch) * 1099511628211ULL;
    h = (h ^ 0xff) * 1099511628211ULL;
  };
  const long n = CaseCount(c);
  for (long k = 0; k < n; ++k) {
    const CaseSpec cs = CaseAt(c, k);
    EXPECT_EQ(cs.index, k);
    add(cs.run_id);
    add(std::to_string(cs.seed));
    add(cs.group);
    add(cs.fault.dump());
    add(cs.VariationJson().dump());
    add(std::to_string(cs.trajectory) + "/" + std::to_string(cs.repetition));
  }
  return h;
}

// The digests of the cases as ExpandCases built them before cases were computed by index
// (commit 9d236ec): any change to a run_id, seed, fault or draw changes these.
TEST(CaseAt, ShippedCampaignsKeepEveryCase) {
  const std::pair<const char*, uint64_t> golden[] = {
      {"ci", 16677493871207923387ULL},
      {"five-families", 9705709629721638578ULL},
      {"realistic", 14887480609761030123ULL},
      {"realistic-pod", 717379817731486531ULL},
      {"thesis-sweep", 8916081099280894058ULL}};
  for (const auto& [name, digest] : golden) {
    const Campaign c = ReadCampaignFile(std::string(ARMFAULT_SOURCE_DIR) + "/campaigns/files/" + name + ".json");
    EXPECT_EQ(CasesDigest(c), digest) << name;
  }
}

}  // namespace
}  // namespace armfault

namespace armfault {
namespace {

TEST(CaseAt, EveryIndexInRangeAndNoneOutside) {
  const Campaign c = ReadCampaignFile(std::string(ARMFAULT_SOURCE_DIR) + "/campaigns/files/five-families.json");
  const long n = CaseCount(c);
  EXPECT_EQ(CaseAt(c, n - 1).index, n - 1);
  EXPECT_THROW(CaseAt(c, n), std::out_of_range);
  EXPECT_THROW(CaseAt(c, -1), std::out_of_range);
}

}  // namespace
}  // namespace armfault
