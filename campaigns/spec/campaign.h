// A campaign ready to run: its spec (campaigns/spec/campaign_spec.h: the file's settings, parsed
// and validated) with what is built from it for running: each trajectory loaded (CSV files
// read) and the monitor model. Its cases are in campaigns/cases.h. Reading only the spec
// (CampaignSpecFromJson) is enough for merge, tune and provenance, which neither load
// trajectories nor build a monitor.
#pragma once

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <vector>

#include "core/monitors/registry.h"
#include "campaigns/spec/campaign_spec.h"
#include "campaigns/spec/cases.h"

namespace armfault {

struct Campaign : CampaignSpec {
  // The joints of each of the spec's trajectories, loaded, in the same order.
  LoadedTrajectories loaded_trajectories;
  // The monitor model built once from the spec's "monitor" and the nominal robot (what the
  // monitor knows, MonitorContextOf), shared read-only by every run. A caller may put another
  // model in its place (the Python package does, for a monitor written in Python).
  std::shared_ptr<const MonitorModel> monitor_model;
};

// Parses and validates a campaign and builds it for running; every error names the file, the
// JSON pointer and the value (a trajectory's with the spec's, then the monitor's).
// Whether reading a campaign builds a monitor that runs the user's own code (a plugin library,
// MonitorRunsUserCode): kSkipUserCode leaves monitor_model null for such a monitor (the spec and
// the library's path are still checked), so `validate` runs no code it was not asked to.
enum class MonitorLoading { kBuild, kSkipUserCode };
Campaign CampaignFromJson(const nlohmann::json& value, const std::string& source, const std::string& base_dir,
                          MonitorLoading loading = MonitorLoading::kBuild);
Campaign ReadCampaignFile(const std::string& path, MonitorLoading loading = MonitorLoading::kBuild);
// The built-in quick thesis sweep (`armfault run` without a file).
Campaign DefaultCampaign();

// What `validate` (and `run`) warn about in a valid campaign, one line each, naming the JSON
// pointer: a fault entry that targets a joint one of the trajectories leaves still (its runs
// there will be not excited when the family shows only in motion).
std::vector<std::string> CampaignWarnings(const Campaign& campaign);

}  // namespace armfault
