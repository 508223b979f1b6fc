// Fuzz target: a campaign file's text, read as `armfault validate` reads it (ParseJsonText,
// CampaignFromJson: spec, trajectories, monitor model), then what validate prints from it
// (case count, warnings) and the first and last case with their robot. Files named inside
// (a csv trajectory, a monitor file) resolve against a directory that cannot exist.
#include "campaigns/spec/campaign.h"
#include "campaigns/spec/cases.h"
#include "core/plant/simulation.h"
#include "tests/fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace armfault;
  return fuzz::RejectCleanly([&] {
    const nlohmann::json value = ParseJsonText(fuzz::Text(data, size), fuzz::kSource);
    if (fuzz::MentionsPlugin(value)) return;
    const Campaign campaign = CampaignFromJson(value, fuzz::kSource, fuzz::kNoDir);
    const long cases = CaseCount(campaign);
    CampaignWarnings(campaign);
    if (cases <= 0) return;
    for (const long index : {0L, cases - 1}) {
      const CaseSpec spec = CaseAt(campaign, index);
      const ArmModel model(CaseRobot(campaign, spec));
      (void)model;
    }
  });
}
