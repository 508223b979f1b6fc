// `armfault diff`: what changed between two campaign results, A (the baseline) and B (the
// candidate), metric by metric, with a significance test for each change. Pure functions;
// the only I/O is ReadCampaignResults. See docs/campaign-format.md, "armfault diff".
//
// Source of truth: each directory's results.jsonl, read with RunRecordFromJson and tallied
// by SummaryBuilder, so every count follows summary.json's definitions exactly (failed runs
// count nowhere; a faulty run is an ok record with a family, a healthy run one without).
// summary.json, when present, is only cross-checked (a warning if its overall counts differ).
//
// Scopes, in output order:
//   1. "overall": every run of the groups present in both directories;
//   2. "family": per fault family, over the groups present in both (sorted by family);
//   3. "group": per `group` key (family x magnitude x joint, e.g. "kt_degradation
//      kt_factor=0.7 joint=3"), for each group present in both (sorted by key).
// Groups present in only one directory are listed, not compared; when every group is
// common, the overall and family figures equal summary.json's.
//
// Metrics, in output order within a scope (all as in summary.json):
//   detection           detected faulty runs / faulty runs                   higher is better
//   false_alarm         healthy runs with `detected` / healthy runs         lower is better
//   alarm_before_onset  faulty runs with `alarm_before_onset` / faulty runs  lower is better
//                       (the per-family "false alarm" of the floors)
//   isolation           right family and joint / detected faulty runs        higher is better
//   latency             latency_s of detected faulty runs; median (mean of the two middle
//                       values for even n)                                   lower is better
// The faulty-run metrics appear where the scope has faulty runs in A or B; false_alarm where
// it has healthy runs in A or B (overall; a group only if it differs from overall's).
//
// Statistics:
//   - Rates: change = rate_B - rate_A. Two-sided Fisher exact test on the 2x2 table
//     [[s_A, n_A - s_A], [s_B, n_B - s_B]]: conditional on the margins, the hypergeometric
//     probabilities of every table are summed over those no more probable than the observed
//     one (relative tolerance 1e-7, as R's fisher.test): Boost.Math's hypergeometric
//     distribution, its two tails beyond the mode (accurate for large n; at most 2^32 - 1
//     trials in all). The 95 % interval of the change is Newcombe's
//     hybrid score interval (method 10 of Newcombe 1998) built from the Wilson intervals of
//     campaign_summary.h: [d - sqrt((p_B - l_B)^2 + (u_A - p_A)^2),
//                          d + sqrt((u_B - p_B)^2 + (p_A - l_A)^2)].
//   - Latency: change = median_B - median_A (the median shift, seconds). Two-sided
//     Mann-Whitney U test: U_B = pairs (a, b) with b > a, ties counting 1/2. Exact null
//     distribution when both samples have fewer than 50 values and no value is tied (test
//     "mann_whitney_exact"; counted here: Boost.Math has no Mann-Whitney distribution); otherwise
//     the normal approximation (Boost.Math's normal distribution) with the tie correction
//     Var U = n_A n_B / 12 * ((N + 1) - sum(t^3 - t) / (N (N - 1))) and a continuity
//     correction of 1/2 (test "mann_whitney_normal", as R's wilcox.test).
//   - A comparison with no trials (or no latencies) on a side is not tested: verdict "n/a".
//   - Verdict: "worse" when p < alpha and the worsening (the change in the bad direction)
//     exceeds the tolerance (rates: --tolerance, an absolute rate difference; latency:
//     --latency-tolerance in seconds); "better" when p < alpha and the change is in the good
//     direction; "inconclusive" when p >= alpha and the samples cannot show a change: no
//     outcome of these sample sizes could reach p < alpha (SmallestFisherP,
//     SmallestMannWhitneyP: 2 runs against 2 never can, whatever they do), or the change seen
//     is material (|change| >= MaterialRateChange: the rate tolerance, at least 0.1;
//     MaterialLatencyChange: the latency tolerance, at least 0.1 s) but not significant
//     (4/4 -> 2/4, p = 0.43); else "same" (this includes a significant worsening within the
//     tolerance). "inconclusive" does not fail the exit status; only "worse" does.
//   No correction for multiple comparisons is made: with many groups, some "worse" verdicts
//   at alpha = 0.05 are expected by chance when B's runs differ from A's (other seeds).
#pragma once

#include <nlohmann/json.hpp>

#include <istream>
#include <optional>
#include <string>
#include <vector>

#include "campaigns/scoring/campaign_summary.h"

namespace armfault {

struct DiffOptions {
  double alpha = 0.05;              // significance level, in (0, 1]
  double rate_tolerance = 0;        // allowed worsening of a rate, in [0, 1]
  double latency_tolerance_s = 0;   // allowed increase of the median latency [s], >= 0
};
// Throws InputError naming the option (--alpha, --tolerance, --latency-tolerance).
void CheckDiffOptions(const DiffOptions& options);

// ---- statistics (exposed for the tests) ----

// Two-sided Fisher exact p-value for s_a of n_a against s_b of n_b. Throws
// std::invalid_argument unless 0 <= s <= n and n > 0 on both sides.
double FisherExactTwoSided(long s_a, long n_a, long s_b, long n_b);

// The smallest two-sided p any outcome of these sample sizes can give: Fisher's at n_a of n_a
// against 0 of n_b (2 runs a side: 0.333); Mann-Whitney's exact at every B beyond every A,
// 2 / C(n_a + n_b, n_a) (3 a side: 0.1). 1 when a side is empty.
double SmallestFisherP(long n_a, long n_b);
double SmallestMannWhitneyP(long n_a, long n_b);
// What diff calls a material change (docs/assumptions.md): a rate difference of 0.1 and a
// median-latency shift of 0.1 s, or the tolerance given when larger.
constexpr double kMaterialRateChange = 0.1;
constexpr double kMaterialLatencyChange_s = 0.1;
double MaterialRateChange(const DiffOptions& options);
double MaterialLatencyChange(const DiffOptions& options);

// rate_B - rate_A with its 95 % Newcombe hybrid score interval (clamped to [-1, 1]).
struct DifferenceInterval {
  double difference = 0, low = 0, high = 0;
};
DifferenceInterval NewcombeDifference(long s_a, long n_a, long s_b, long n_b);

struct MannWhitneyResult {
  double u_b = 0;      // pairs with b > a, plus half the tied pairs; U_A = n_A n_B - U_B
  double z = 0;        // normal approximation (0 when exact)
  double p = 1;        // two-sided
  bool exact = false;  // exact null distribution (n < 50 each, no ties)
};
// Throws std::invalid_argument if either sample is empty.
MannWhitneyResult MannWhitney(const std::vector<double>& a, const std::vector<double>& b);

// Median as in summary.json (mean of the two middle values for even n); nullopt if empty.
std::optional<double> Median(std::vector<double> values);

// ---- inputs ----

// One campaign result directory.
struct CampaignResults {
  std::string label;                    // how the output names it (the directory)
  nlohmann::json campaign;              // campaign.json's "campaign"; null if unknown
  SummaryBuilder records;               // every record of results.jsonl
  std::vector<std::string> warnings;    // e.g. a summary.json that disagrees
};

// Reads DIR/results.jsonl (required), DIR/campaign.json (optional: without it the campaign
// is unknown; unparsable is an error) and cross-checks DIR/summary.json (optional; a
// mismatch or an unreadable one only warns). Throws InputError naming the directory or file.
CampaignResults ReadCampaignResults(const std::string& dir);

// ---- the diff ----

struct DiffSideValue {
  long successes = 0, trials = 0;        // rates
  long count = 0;                        // latency: values
  std::optional<double> value;           // the rate or the median latency; nullopt if none
};

struct Comparison {
  std::string scope;    // "overall", "family", "group"
  std::string name;     // "" (overall), the family, or the group key
  std::string family;   // the group's family ("" for overall and healthy-only groups)
  std::string metric;   // "detection", "false_alarm", "alarm_before_onset", "isolation", "latency"
  bool is_rate = true;
  bool higher_is_better = true;
  DiffSideValue a, b;
  std::optional<double> change;            // B - A (rate, or median seconds)
  std::optional<double> ci_low, ci_high;   // rates: Newcombe 95 % interval of the change
  std::optional<double> p;                 // two-sided p-value; nullopt: not tested
  std::string test;                        // "fisher_exact", "mann_whitney_exact", "mann_whitney_normal", ""
  std::optional<double> u_b, z;            // latency: Mann-Whitney U of B and z (normal only)
  bool significant = false;                // p < alpha
  std::string verdict;                     // "better", "worse", "same", "inconclusive", "n/a"
};

struct DiffSide {
  std::string label;
  std::string campaign_name;  // "" if unknown
  long runs = 0, failed = 0;
  // Left out of every rate, as summary.json leaves them out (not excited: unless the campaign
  // sets include_not_excited, then scored and counted here all the same).
  long not_excited = 0, not_injected = 0;
  bool not_excited_included = false;
};

struct DiffResult {
  DiffOptions options;
  DiffSide a, b;
  bool campaigns_known = false;             // both directories have a campaign.json
  bool same_campaign = false;               // both campaign.json "campaign" known and equal
  std::vector<std::string> campaign_differences;  // top-level campaign keys that differ, sorted
  long common_groups = 0;
  std::vector<std::string> groups_only_in_a, groups_only_in_b;      // sorted
  std::vector<std::string> families_only_in_a, families_only_in_b;  // sorted
  std::vector<Comparison> comparisons;      // in the order documented above
  std::vector<std::string> warnings;        // both sides' reading warnings, then the diff's

  long Count(const std::string& verdict) const;
  bool AnyWorse() const { return Count("worse") > 0; }
};

DiffResult DiffCampaigns(const CampaignResults& a, const CampaignResults& b, const DiffOptions& options);

// diff.json: {"armfault_version", "options": {"alpha", "tolerance", "latency_tolerance_s"},
//  "a"/"b": {"dir", "campaign", "runs", "failed", "not_excited", "not_excited_included",
//            "not_injected"}, "same_campaign", "campaign_differences",
//  "common_groups", "only_in_a"/"only_in_b": {"groups", "families"},
//  "comparisons": [{"scope", "name", "family", "metric", "better": "higher"|"lower",
//                   "a"/"b": {"successes", "trials", "rate"} | {"count", "median_s"},
//                   "change", "ci_low", "ci_high", "p", "test", "u_b", "z", "significant",
//                   "verdict"}],
//  "counts": {"better", "worse", "same", "inconclusive", "n/a"}, "worse": bool, "warnings": [...]}
// Absent values are null. Healthy-only groups (key "") are named "" as in summary.json.
nlohmann::json DiffToJson(const DiffResult& diff);
// A header, one aligned table row per comparison (scope, metric, A, B, change, p, verdict),
// the groups in one directory only, one "worse: ..." line per worse comparison and a count.
std::string DiffToText(const DiffResult& diff);
// The same as a Markdown document (a GitHub table).
std::string DiffToMarkdown(const DiffResult& diff);
// `same campaign "<name>"`, or `the campaigns differ in: <keys>; comparisons are by group
// key`, or that they cannot be compared (a campaign.json missing).
std::string DiffCampaignLine(const DiffResult& diff);
// The "worse: ..." lines alone (one per worse comparison, each ending in a newline).
std::string DiffWorseLines(const DiffResult& diff);

}  // namespace armfault
