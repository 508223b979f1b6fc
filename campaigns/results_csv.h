// results.csv: one flat row per run, beside results.jsonl, for spreadsheets and pandas
// (`pandas.read_csv("results.csv")`). Columns, in this order (docs/campaign-format.md,
// "results.csv"); empty cells where results.jsonl has null:
//   case, run_id, trajectory, group, family, joint, onset_s, magnitude_key, magnitude, seed,
//   repetition, unit, ambient_C, status, reason, took_effect, detected, alarm_before_onset,
//   detection_time_s, latency_s, isolated_family, isolated_joint, isolated (family and joint
//   right), magnitude_name, magnitude_estimate, confidence
// Fields are quoted as RFC 4180 says (run ids hold commas). Numbers are written with 9
// significant digits.
#pragma once

#include <string>

#include "campaigns/run_record.h"

namespace armfault {

std::string ResultsCsvHeader();  // with its newline
std::string ResultsCsvRow(const RunRecord& r);  // with its newline

}  // namespace armfault
