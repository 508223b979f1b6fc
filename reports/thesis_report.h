// Writers for the thesis experiments: thesis.json and a Markdown table, side by side with
// the published figures.
//   thesis.json: {"armfault_version", "seed", "experiments": [{id, title, motion, fault}],
//                 "table_5_3": [{"kt_factor", "thesis_pct", "armfault_pct", "thesis_ratio",
//                                "armfault_ratio", "windows"}],
//                 "experiment_2": [same keys], "experiment_3": [{"spring_load", ...}]}
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "campaigns/thesis/thesis.h"

namespace armfault {

nlohmann::json ThesisToJson(const ThesisResults& results);
std::string ThesisToMarkdown(const ThesisResults& results);

}  // namespace armfault
