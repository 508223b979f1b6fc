// results.csv: one flat row per run, beside results.jsonl, for spreadsheets and pandas
// (`pandas.read_csv("results.csv")`). Columns, in this order (docs/campaign-format.md,
// "results.csv"); empty cells where results.jsonl has null:
//   case, run_id, trajectory, group, family, joint, onset_s, magnitude_key, magnitude, seed,
//   repetition, unit, ambient_C, status, reason, took_effect, detected, alarm_before_onset,
//   detection_time_s, latency_s, isolated_family, isolated_joint, isolated (family and joint
//   right), magnitude_name, magnitude_estimate, confidence, magnitude_unit (of `magnitude`:
//   "1" for a factor or fraction, "Ω", "N m/s"; empty without a magnitude), miss_reason
// Time columns carry their unit in their name (_s, _C); integer columns (case, joint, seed,
// repetition, unit, isolated_joint) are written as integers, booleans as true/false.
// Fields are quoted as RFC 4180 says (run ids hold commas). Numbers are written with 9
// significant digits.
#pragma once

#include <string>

#include "campaigns/scoring/run_record.h"

namespace armfault {

std::string ResultsCsvHeader();  // with its newline
std::string ResultsCsvRow(const RunRecord& r);  // with its newline
// The unit of a magnitude key's values as results.csv writes it: "1" for a ratio (kt_factor,
// friction_factor, drag_fraction, resistance_factor), "Ω" (resistance_ohm), "N m/s"
// (drift_Nm_per_s); "" for an unknown key.
std::string MagnitudeUnit(const std::string& magnitude_key);

}  // namespace armfault
