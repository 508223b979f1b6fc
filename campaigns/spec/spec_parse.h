// The parts of a campaign spec's parsing shared by its files (internal to campaigns/:
// campaign_spec.cc reads the file's top level, fault_entry.cc the fault entries and their
// sweeps, search_spec.cc the "search" block). Every error is an InputError naming the JSON
// pointer; the caller adds the file.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "core/base/json_input.h"
#include "campaigns/spec/campaign_spec.h"

namespace armfault {
namespace spec_parse {

// A key's values. `swept` tells a list, grid or uniform from a single fixed value.
struct ParsedSweep {
  Sweep sweep;
  bool swept = false;
};

// A list, a grid {"from","to","steps"}, a {"uniform": [a, b]} or one value; `numbers_only`:
// strings and booleans are refused.
ParsedSweep ParseSweep(const nlohmann::json& v, const std::string& pointer, bool numbers_only);

// One fault entry (or compound entry) of "faults". Reports every error of the entry it can
// find. Without a robot (the campaign's own is bad) only the entry's shape is checked: the
// family's checks need the robot's joints.
FaultEntry ParseFaultEntry(const nlohmann::json& v, const std::string& pointer, const RobotConfig* robot);

// The "search" block (docs/campaign-format.md, "Boundary search") into c->search. Needs the
// fault entries parsed (`faults_ok`) and the robot for the family checks of the range's ends
// (`robot_ok`); adds its errors to `errors`.
void ParseSearch(const nlohmann::json& v, const std::string& pointer, CampaignSpec* c, bool faults_ok, bool robot_ok,
                 ErrorList* errors);

}  // namespace spec_parse
}  // namespace armfault
