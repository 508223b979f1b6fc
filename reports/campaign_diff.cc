#include "reports/campaign_diff.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>

#include <boost/math/distributions/hypergeometric.hpp>

#include "campaigns/running/run_dir.h"
#include "core/base/distributions.h"
#include "core/base/json_input.h"

namespace armfault {

namespace {

namespace fs = std::filesystem;
using internal::SummaryTally;

const char* const kVerdicts[] = {"better", "worse", "same", "inconclusive", "n/a"};

void CheckCounts(long s, long n, const char* who) {
  if (n <= 0 || s < 0 || s > n) {
    throw std::invalid_argument(std::string(who) + ": need 0 <= successes <= trials and trials > 0, got " +
                                std::to_string(s) + " of " + std::to_string(n));
  }
}

// Exact null distribution of U_B for sample sizes m (A) and n (B) without ties: the number of
// orderings of m A's and n B's with u pairs (a, b), b > a, for u = 0 .. m n. Counts are
// doubles (C(98, 49) ~ 2.5e28 is far below the double range; every step adds positives).
// By the largest value: count(i, j, u) = count(i, j - 1, u - i) [a B above all i A's]
//                                       + count(i - 1, j, u)     [an A, above no B].
std::vector<double> ExactUDistribution(size_t m, size_t n) {
  const size_t max_u = m * n;
  // f[i][u] = count(i, j, u) for the current j.
  std::vector<std::vector<double>> f(m + 1, std::vector<double>(max_u + 1, 0.0));
  for (size_t i = 0; i <= m; ++i) f[i][0] = 1;  // j = 0: no B, U = 0
  for (size_t j = 1; j <= n; ++j) {
    // count(0, j, 0) = 1 stays; for i >= 1: new f[i][u] = old f[i][u - i] + new f[i - 1][u].
    for (size_t i = 1; i <= m; ++i) {
      std::vector<double> next(max_u + 1, 0.0);
      for (size_t u = 0; u <= max_u; ++u) {
        next[u] = f[i - 1][u] + (u >= i ? f[i][u - i] : 0.0);
      }
      f[i] = std::move(next);
    }
  }
  return f[m];
}

std::string Fixed(double x, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, x);
  return buf;
}
std::string Signed(double x, int digits) {
  char buf[64];
  // No "-0.000": a change that rounds to zero prints as +0.000.
  const double shown = std::fabs(x) < 0.5 * std::pow(10.0, -digits) ? 0.0 : x;
  std::snprintf(buf, sizeof buf, "%+.*f", digits, shown);
  return buf;
}
std::string PValue(const std::optional<double>& p) {
  if (!p) return "-";
  if (*p < 1e-4) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1e", *p);
    return buf;
  }
  return Fixed(*p, 4);
}

std::string ScopeLabel(const Comparison& c) {
  if (c.scope == "overall") return "overall";
  if (c.scope == "family") return "family " + c.name;
  return c.name.empty() ? "(healthy runs)" : c.name;
}
std::string GroupLabel(const std::string& g) { return g.empty() ? "(healthy runs)" : g; }

std::string SideText(const Comparison& c, const DiffSideValue& v) {
  if (c.is_rate) {
    if (v.trials == 0) return "- (0/0)";
    return Fixed(*v.value, 3) + " (" + std::to_string(v.successes) + "/" + std::to_string(v.trials) + ")";
  }
  if (!v.value) return "- (n=0)";
  return Fixed(*v.value, 3) + " s (n=" + std::to_string(v.count) + ")";
}

std::string ChangeText(const Comparison& c) {
  if (!c.change) return "-";
  if (!c.is_rate) return Signed(*c.change, 3) + " s";
  std::string s = Signed(*c.change, 3);
  if (c.ci_low && c.ci_high) s += " [" + Signed(*c.ci_low, 3) + ", " + Signed(*c.ci_high, 3) + "]";
  return s;
}

std::string VerdictText(const Comparison& c) {
  if (c.verdict == "same" && c.significant) return "same (within tolerance)";
  return c.verdict;
}

std::string OptionsLine(const DiffOptions& o) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "alpha %g, tolerance %g (rates), %g s (latency)", o.alpha, o.rate_tolerance,
                o.latency_tolerance_s);
  return buf;
}

std::string SideLine(const char* which, const DiffSide& s) {
  std::string line = std::string(which) + " = " + s.label + " (campaign " +
                     (s.campaign_name.empty() ? std::string("unknown") : "\"" + s.campaign_name + "\"") + ", " +
                     std::to_string(s.runs) + " runs, " + std::to_string(s.failed) + " failed" +
                     (s.not_excited > 0 ? ", " + std::to_string(s.not_excited) + " not excited" +
                                              (s.not_excited_included ? " (scored)" : ", left out")
                                        : std::string()) +
                     (s.not_injected > 0 ? ", " + std::to_string(s.not_injected) + " not injected, left out" : std::string()) +
                     ")";
  return line;
}

}  // namespace

std::string DiffCampaignLine(const DiffResult& d) {
  if (d.same_campaign) return "same campaign \"" + d.a.campaign_name + "\"";
  if (!d.campaigns_known) return "the campaigns cannot be compared (no campaign.json); comparisons are by group key";
  std::string s = "the campaigns differ";
  if (!d.campaign_differences.empty()) {
    s += " in:";
    for (const std::string& k : d.campaign_differences) s += " " + k;
  }
  return s + "; comparisons are by group key";
}

namespace {

nlohmann::json OptJson(const std::optional<double>& x) { return x ? nlohmann::json(*x) : nlohmann::json(nullptr); }

// Pools a side's cells by group (and remembers the group's family as summary.json does).
struct Pooled {
  std::map<std::string, SummaryTally> groups;
  std::map<std::string, std::string> group_family;
  std::map<std::string, std::map<std::string, std::vector<const SummaryTally*>>> cells_by_group;  // group -> family -> cells
};

Pooled Pool(const SummaryBuilder& b) {
  Pooled p;
  for (const auto& [key, t] : b.cells()) {
    internal::MergeTally(t, &p.groups[key.first]);
    std::string& fam = p.group_family[key.first];
    if (fam.empty()) fam = key.second;
    p.cells_by_group[key.first][key.second].push_back(&t);
  }
  return p;
}

Comparison RateComparison(const std::string& metric, bool higher_is_better, long s_a, long n_a, long s_b, long n_b,
                          const DiffOptions& o) {
  Comparison c;
  c.metric = metric;
  c.is_rate = true;
  c.higher_is_better = higher_is_better;
  c.a.successes = s_a;
  c.a.trials = n_a;
  c.b.successes = s_b;
  c.b.trials = n_b;
  if (n_a > 0) c.a.value = static_cast<double>(s_a) / static_cast<double>(n_a);
  if (n_b > 0) c.b.value = static_cast<double>(s_b) / static_cast<double>(n_b);
  if (n_a == 0 || n_b == 0) {
    c.verdict = "n/a";
    return c;
  }
  const DifferenceInterval d = NewcombeDifference(s_a, n_a, s_b, n_b);
  c.change = d.difference;
  c.ci_low = d.low;
  c.ci_high = d.high;
  c.p = FisherExactTwoSided(s_a, n_a, s_b, n_b);
  c.test = "fisher_exact";
  c.significant = *c.p < o.alpha;
  const double worsening = higher_is_better ? -d.difference : d.difference;
  if (c.significant && worsening > o.rate_tolerance) {
    c.verdict = "worse";
  } else if (c.significant && worsening < 0) {
    c.verdict = "better";
  } else if (!c.significant && (SmallestFisherP(n_a, n_b) >= o.alpha ||
                                std::fabs(d.difference) >= MaterialRateChange(o) - 1e-12)) {
    // Too few runs to show any change, or a material change seen that they cannot confirm.
    c.verdict = "inconclusive";
  } else {
    c.verdict = "same";
  }
  return c;
}

Comparison LatencyComparison(const SummaryTally& a, const SummaryTally& b, const DiffOptions& o) {
  Comparison c;
  c.metric = "latency";
  c.is_rate = false;
  c.higher_is_better = false;
  c.a.count = static_cast<long>(a.latencies_s.size());
  c.b.count = static_cast<long>(b.latencies_s.size());
  c.a.value = Median(a.latencies_s);
  c.b.value = Median(b.latencies_s);
  if (!c.a.value || !c.b.value) {
    c.verdict = "n/a";
    return c;
  }
  c.change = *c.b.value - *c.a.value;
  const MannWhitneyResult mw = MannWhitney(a.latencies_s, b.latencies_s);
  c.p = mw.p;
  c.u_b = mw.u_b;
  if (!mw.exact) c.z = mw.z;
  c.test = mw.exact ? "mann_whitney_exact" : "mann_whitney_normal";
  c.significant = mw.p < o.alpha;
  if (c.significant && *c.change > o.latency_tolerance_s) {
    c.verdict = "worse";
  } else if (c.significant && *c.change < 0) {
    c.verdict = "better";
  } else if (!c.significant && (SmallestMannWhitneyP(static_cast<long>(a.latencies_s.size()),
                                                     static_cast<long>(b.latencies_s.size())) >= o.alpha ||
                                std::fabs(*c.change) >= MaterialLatencyChange(o) - 1e-12)) {
    c.verdict = "inconclusive";
  } else {
    c.verdict = "same";
  }
  return c;
}

// The comparisons of one scope, in the documented metric order.
void CompareScope(const std::string& scope, const std::string& name, const std::string& family,
                  const SummaryTally& a, const SummaryTally& b, bool with_false_alarm, const DiffOptions& o,
                  std::vector<Comparison>* out) {
  std::vector<Comparison> v;
  const bool faulty = a.faulty > 0 || b.faulty > 0;
  if (faulty) v.push_back(RateComparison("detection", true, a.detected, a.faulty, b.detected, b.faulty, o));
  if (with_false_alarm && (a.healthy > 0 || b.healthy > 0)) {
    v.push_back(RateComparison("false_alarm", false, a.healthy_alarms, a.healthy, b.healthy_alarms, b.healthy, o));
  }
  if (faulty) {
    v.push_back(RateComparison("alarm_before_onset", false, a.before_onset, a.faulty, b.before_onset, b.faulty, o));
    v.push_back(RateComparison("isolation", true, a.isolated, a.detected, b.isolated, b.detected, o));
    v.push_back(LatencyComparison(a, b, o));
  }
  for (Comparison& c : v) {
    c.scope = scope;
    c.name = name;
    c.family = family;
    out->push_back(std::move(c));
  }
}

// Escapes a Markdown table cell.
std::string Cell(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '|') out += "\\|";
    else if (c == '\n') out += ' ';
    else out += c;
  }
  return out;
}

}  // namespace

void CheckDiffOptions(const DiffOptions& o) {
  if (!(o.alpha > 0 && o.alpha <= 1)) {
    throw InputError("--alpha", "", FormatNumber(o.alpha) + " is outside (0, 1]");
  }
  if (!(o.rate_tolerance >= 0 && o.rate_tolerance <= 1)) {
    throw InputError("--tolerance", "", FormatNumber(o.rate_tolerance) + " is outside [0, 1]");
  }
  if (!(o.latency_tolerance_s >= 0 && std::isfinite(o.latency_tolerance_s))) {
    throw InputError("--latency-tolerance", "", FormatNumber(o.latency_tolerance_s) + " must be a number of seconds >= 0");
  }
}

double FisherExactTwoSided(long s_a, long n_a, long s_b, long n_b) {
  CheckCounts(s_a, n_a, "FisherExactTwoSided");
  CheckCounts(s_b, n_b, "FisherExactTwoSided");
  if (n_a + n_b > static_cast<long>(std::numeric_limits<unsigned>::max())) {
    throw std::invalid_argument("FisherExactTwoSided: " + std::to_string(n_a + n_b) + " trials in all is beyond " +
                                std::to_string(std::numeric_limits<unsigned>::max()));
  }
  // Margins: row totals n_a, n_b; column total k successes. X = successes in A is
  // hypergeometric: k successes among the n_a + n_b trials, n_a of them drawn (Boost.Math:
  // r = k "defective" items, sample size n_a, population n_a + n_b), on
  // x in [max(0, k - n_b), min(n_a, k)].
  const unsigned k = static_cast<unsigned>(s_a + s_b);
  const boost::math::hypergeometric_distribution<double> h(k, static_cast<unsigned>(n_a),
                                                           static_cast<unsigned>(n_a + n_b));
  const unsigned lo = boost::math::range(h).first, hi = boost::math::range(h).second;
  auto density = [&h](unsigned x) { return boost::math::pdf(h, x); };
  // R's fisher.test: the tables with density <= observed * (1 + 1e-7). The hypergeometric is
  // unimodal, so they are the two tails [lo, a] and [b, hi] around the mode: their ends by a
  // binary search on the density, their probabilities by Boost's cdf (no pass over the whole
  // support: a million tables take microseconds).
  const double limit = density(static_cast<unsigned>(s_a)) * (1 + 1e-7);
  const unsigned mode = boost::math::mode(h);
  if (density(mode) <= limit) return 1.0;  // the observed table is as probable as the mode's
  double p = 0;
  if (density(lo) <= limit) {  // the largest a in [lo, mode) with density(a) <= limit
    unsigned in = lo, out = mode;
    while (out - in > 1) {
      const unsigned mid = in + (out - in) / 2;
      (density(mid) <= limit ? in : out) = mid;
    }
    p += boost::math::cdf(h, in);
  }
  if (density(hi) <= limit) {  // the smallest b in (mode, hi] with density(b) <= limit
    unsigned out = mode, in = hi;
    while (in - out > 1) {
      const unsigned mid = out + (in - out) / 2;
      (density(mid) <= limit ? in : out) = mid;
    }
    p += boost::math::cdf(boost::math::complement(h, in - 1));  // P(X >= in)
  }
  return std::min(1.0, p);
}

double SmallestFisherP(long n_a, long n_b) {
  if (n_a <= 0 || n_b <= 0) return 1;
  return FisherExactTwoSided(n_a, n_a, 0, n_b);
}

double SmallestMannWhitneyP(long n_a, long n_b) {
  if (n_a <= 0 || n_b <= 0) return 1;
  // Every B above every A (or below): probability 1 / C(n_a + n_b, n_a) each, two-sided.
  const double log_choose = std::lgamma(n_a + n_b + 1.0) - std::lgamma(n_a + 1.0) - std::lgamma(n_b + 1.0);
  return std::min(1.0, 2 * std::exp(-log_choose));
}

double MaterialRateChange(const DiffOptions& o) { return std::max(o.rate_tolerance, kMaterialRateChange); }
double MaterialLatencyChange(const DiffOptions& o) { return std::max(o.latency_tolerance_s, kMaterialLatencyChange_s); }

DifferenceInterval NewcombeDifference(long s_a, long n_a, long s_b, long n_b) {
  CheckCounts(s_a, n_a, "NewcombeDifference");
  CheckCounts(s_b, n_b, "NewcombeDifference");
  const RateInterval wa = Wilson(s_a, n_a), wb = Wilson(s_b, n_b);
  const double d = wb.rate - wa.rate;
  DifferenceInterval r;
  r.difference = d;
  r.low = std::max(-1.0, d - std::sqrt((wb.rate - wb.low) * (wb.rate - wb.low) + (wa.high - wa.rate) * (wa.high - wa.rate)));
  r.high = std::min(1.0, d + std::sqrt((wb.high - wb.rate) * (wb.high - wb.rate) + (wa.rate - wa.low) * (wa.rate - wa.low)));
  return r;
}

MannWhitneyResult MannWhitney(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.empty() || b.empty()) throw std::invalid_argument("MannWhitney: both samples must be non-empty");
  const size_t m = a.size(), n = b.size(), total = m + n;
  std::vector<std::pair<double, int>> all;  // (value, 0 = A, 1 = B)
  all.reserve(total);
  for (double x : a) all.emplace_back(x, 0);
  for (double x : b) all.emplace_back(x, 1);
  std::sort(all.begin(), all.end());
  // Mid-ranks (1-based) and the tie term sum(t^3 - t).
  double rank_sum_b = 0, tie_term = 0;
  bool ties = false;
  for (size_t i = 0; i < total;) {
    size_t j = i;
    while (j < total && all[j].first == all[i].first) ++j;
    const double t = static_cast<double>(j - i);
    const double mid = (static_cast<double>(i + 1) + static_cast<double>(j)) / 2;
    for (size_t q = i; q < j; ++q) {
      if (all[q].second == 1) rank_sum_b += mid;
    }
    if (j - i > 1) {
      ties = true;
      tie_term += t * t * t - t;
    }
    i = j;
  }
  const double dm = static_cast<double>(m), dn = static_cast<double>(n), dN = static_cast<double>(total);
  MannWhitneyResult r;
  r.u_b = rank_sum_b - dn * (dn + 1) / 2;
  const double mean = dm * dn / 2;
  if (!ties && m < 50 && n < 50) {
    r.exact = true;
    const std::vector<double> dist = ExactUDistribution(m, n);  // U_B: B's values above A's
    double all_count = 0;
    for (double c : dist) all_count += c;
    const double u_low = std::min(r.u_b, dm * dn - r.u_b);  // integral here: no ties
    double tail = 0;
    for (size_t u = 0; u < dist.size() && static_cast<double>(u) <= u_low + 1e-9; ++u) tail += dist[u];
    r.p = std::min(1.0, 2 * tail / all_count);
    return r;
  }
  const double variance = dm * dn / 12 * ((dN + 1) - tie_term / (dN * (dN - 1)));
  if (!(variance > 0)) {  // every value tied: no evidence of a shift
    r.p = 1;
    return r;
  }
  const double diff = r.u_b - mean;
  const double correction = diff > 0 ? 0.5 : (diff < 0 ? -0.5 : 0.0);
  r.z = (diff - correction) / std::sqrt(variance);
  r.p = std::min(1.0, 2 * StandardNormalUpperTail(std::fabs(r.z)));
  return r;
}

std::optional<double> Median(std::vector<double> v) {
  if (v.empty()) return std::nullopt;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

CampaignResults ReadCampaignResults(const std::string& dir_name) {
  const fs::path dir(dir_name);
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw InputError(dir_name, "", "no such directory");
  if (!fs::is_directory(dir, ec)) throw InputError(dir_name, "", "not a directory (expected a campaign output directory)");
  CampaignResults r;
  r.label = dir_name;
  const fs::path results = dir / run_dir::kResults;
  if (!fs::exists(results, ec)) {
    throw InputError(results.string(), "", "no such file (is " + dir_name + " an armfault run output directory?)");
  }
  const fs::path campaign = dir / run_dir::kCampaign;
  if (fs::exists(campaign, ec)) {
    r.campaign = ReadCampaignFileJson(dir).at("campaign");
  } else {
    r.warnings.push_back(campaign.string() + " is missing: the campaign is unknown");
  }
  // The runs summary.json leaves out (not excited, unless the campaign scores them) are left
  // out here too: one denominator in every command.
  const nlohmann::json* include = r.campaign.is_object() && r.campaign.contains("include_not_excited")
                                      ? &r.campaign["include_not_excited"]
                                      : nullptr;
  r.records = SummaryBuilder(include != nullptr && include->is_boolean() && include->get<bool>());
  JsonLinesOptions lines;
  lines.open_error = "cannot open the file for reading";
  ReadRunRecords(results, lines, [&](RunRecord&& record, long) { r.records.Add(record); });
  // Cross-check: summary.json's overall counts against the records (a stale summary warns).
  const fs::path summary = dir / run_dir::kSummary;
  if (fs::exists(summary, ec)) {
    try {
      const nlohmann::json s = ReadJsonFile(summary.string());
      SummaryTally all;
      for (const auto& [key, t] : r.records.cells()) internal::MergeTally(t, &all);
      const nlohmann::json& o = s.at("overall");
      const bool same = o.at("detection").at("successes").get<long>() == all.detected &&
                        o.at("detection").at("trials").get<long>() == all.faulty &&
                        o.at("false_alarm").at("successes").get<long>() == all.healthy_alarms &&
                        o.at("false_alarm").at("trials").get<long>() == all.healthy &&
                        o.at("isolation").at("successes").get<long>() == all.isolated &&
                        o.at("alarm_before_onset_rate").at("successes").get<long>() == all.before_onset;
      if (!same) {
        r.warnings.push_back(summary.string() + " does not match " + results.string() +
                             " (stale?); the diff uses results.jsonl");
      }
    } catch (const std::exception& e) {
      r.warnings.push_back(summary.string() + " could not be cross-checked (" + e.what() + "); the diff uses results.jsonl");
    }
  }
  return r;
}

long DiffResult::Count(const std::string& verdict) const {
  long n = 0;
  for (const Comparison& c : comparisons) n += c.verdict == verdict ? 1 : 0;
  return n;
}

DiffResult DiffCampaigns(const CampaignResults& a, const CampaignResults& b, const DiffOptions& o) {
  CheckDiffOptions(o);
  DiffResult d;
  d.options = o;
  auto side = [](const CampaignResults& r) {
    DiffSide s;
    s.label = r.label;
    if (r.campaign.is_object() && r.campaign.contains("name") && r.campaign["name"].is_string()) {
      s.campaign_name = r.campaign["name"].get<std::string>();
    }
    s.runs = r.records.runs();
    s.failed = r.records.failed_runs();
    s.not_excited = r.records.not_excited_runs();
    s.not_excited_included = r.records.includes_not_excited();
    s.not_injected = r.records.not_injected_runs();
    return s;
  };
  d.a = side(a);
  d.b = side(b);
  d.warnings = a.warnings;
  d.warnings.insert(d.warnings.end(), b.warnings.begin(), b.warnings.end());

  d.campaigns_known = !a.campaign.is_null() && !b.campaign.is_null();
  d.same_campaign = d.campaigns_known && a.campaign == b.campaign;
  if (!d.same_campaign && a.campaign.is_object() && b.campaign.is_object()) {
    std::set<std::string> keys;
    for (const auto& [k, v] : a.campaign.items()) keys.insert(k);
    for (const auto& [k, v] : b.campaign.items()) keys.insert(k);
    for (const std::string& k : keys) {
      if (!a.campaign.contains(k) || !b.campaign.contains(k) || a.campaign[k] != b.campaign[k]) {
        d.campaign_differences.push_back(k);
      }
    }
  }
  for (const DiffSide* s : {&d.a, &d.b}) {
    if (s->failed > 0) {
      d.warnings.push_back(s->label + ": " + std::to_string(s->failed) + " failed runs, left out of every rate");
    }
  }

  const Pooled pa = Pool(a.records), pb = Pool(b.records);
  std::vector<std::string> common;
  for (const auto& [g, t] : pa.groups) {
    if (pb.groups.count(g)) common.push_back(g);
    else d.groups_only_in_a.push_back(g);
  }
  for (const auto& [g, t] : pb.groups) {
    if (!pa.groups.count(g)) d.groups_only_in_b.push_back(g);
  }
  d.common_groups = static_cast<long>(common.size());

  // Overall and families pool the common groups only: like for like.
  SummaryTally overall_a, overall_b;
  std::map<std::string, std::pair<SummaryTally, SummaryTally>> families;
  std::set<std::string> fam_a, fam_b;
  for (const auto& [g, fams] : pa.cells_by_group) {
    for (const auto& [f, cells] : fams) if (!f.empty()) fam_a.insert(f);
  }
  for (const auto& [g, fams] : pb.cells_by_group) {
    for (const auto& [f, cells] : fams) if (!f.empty()) fam_b.insert(f);
  }
  for (const std::string& f : fam_a) if (!fam_b.count(f)) d.families_only_in_a.push_back(f);
  for (const std::string& f : fam_b) if (!fam_a.count(f)) d.families_only_in_b.push_back(f);
  for (const std::string& g : common) {
    internal::MergeTally(pa.groups.at(g), &overall_a);
    internal::MergeTally(pb.groups.at(g), &overall_b);
    for (const auto& [f, cells] : pa.cells_by_group.at(g)) {
      if (f.empty()) continue;
      for (const SummaryTally* t : cells) internal::MergeTally(*t, &families[f].first);
    }
    for (const auto& [f, cells] : pb.cells_by_group.at(g)) {
      if (f.empty()) continue;
      for (const SummaryTally* t : cells) internal::MergeTally(*t, &families[f].second);
    }
  }
  if (!d.groups_only_in_a.empty() || !d.groups_only_in_b.empty()) {
    d.warnings.push_back("the run sets differ: " + std::to_string(d.groups_only_in_a.size()) + " groups only in A, " +
                         std::to_string(d.groups_only_in_b.size()) +
                         " only in B; overall and family figures pool the " + std::to_string(common.size()) +
                         " groups present in both");
  }

  CompareScope("overall", "", "", overall_a, overall_b, true, o, &d.comparisons);
  for (const auto& [f, t] : families) CompareScope("family", f, f, t.first, t.second, false, o, &d.comparisons);
  for (const std::string& g : common) {
    const SummaryTally& ta = pa.groups.at(g);
    const SummaryTally& tb = pb.groups.at(g);
    // A group's false alarms are compared only where they are not overall's very numbers.
    const bool own_false_alarm = (ta.healthy > 0 || tb.healthy > 0) &&
                                 !(ta.healthy == overall_a.healthy && ta.healthy_alarms == overall_a.healthy_alarms &&
                                   tb.healthy == overall_b.healthy && tb.healthy_alarms == overall_b.healthy_alarms);
    std::string family = pa.group_family.at(g);
    if (family.empty()) family = pb.group_family.at(g);
    CompareScope("group", g, family, ta, tb, own_false_alarm, o, &d.comparisons);
  }
  return d;
}

nlohmann::json DiffToJson(const DiffResult& d) {
  nlohmann::json j;
  j["armfault_version"] = ARMFAULT_VERSION;
  j["options"] = {{"alpha", d.options.alpha},
                  {"tolerance", d.options.rate_tolerance},
                  {"latency_tolerance_s", d.options.latency_tolerance_s}};
  auto side = [](const DiffSide& s) {
    return nlohmann::json{{"dir", s.label},
                          {"campaign", s.campaign_name.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.campaign_name)},
                          {"runs", s.runs},
                          {"failed", s.failed},
                          {"not_excited", s.not_excited},
                          {"not_excited_included", s.not_excited_included},
                          {"not_injected", s.not_injected}};
  };
  j["a"] = side(d.a);
  j["b"] = side(d.b);
  j["same_campaign"] = d.same_campaign;
  j["campaign_differences"] = d.campaign_differences;
  j["common_groups"] = d.common_groups;
  j["only_in_a"] = {{"groups", d.groups_only_in_a}, {"families", d.families_only_in_a}};
  j["only_in_b"] = {{"groups", d.groups_only_in_b}, {"families", d.families_only_in_b}};
  nlohmann::json list = nlohmann::json::array();
  for (const Comparison& c : d.comparisons) {
    nlohmann::json e;
    e["scope"] = c.scope;
    e["name"] = c.name;
    e["family"] = c.family.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.family);
    e["metric"] = c.metric;
    e["better"] = c.higher_is_better ? "higher" : "lower";
    auto value = [&](const DiffSideValue& v) {
      if (c.is_rate) return nlohmann::json{{"successes", v.successes}, {"trials", v.trials}, {"rate", OptJson(v.value)}};
      return nlohmann::json{{"count", v.count}, {"median_s", OptJson(v.value)}};
    };
    e["a"] = value(c.a);
    e["b"] = value(c.b);
    e["change"] = OptJson(c.change);
    e["ci_low"] = OptJson(c.ci_low);
    e["ci_high"] = OptJson(c.ci_high);
    e["p"] = OptJson(c.p);
    e["test"] = c.test.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.test);
    e["u_b"] = OptJson(c.u_b);
    e["z"] = OptJson(c.z);
    e["significant"] = c.significant;
    e["verdict"] = c.verdict;
    list.push_back(std::move(e));
  }
  j["comparisons"] = std::move(list);
  nlohmann::json counts;
  for (const char* v : kVerdicts) counts[v] = d.Count(v);
  j["counts"] = counts;
  j["worse"] = d.AnyWorse();
  j["warnings"] = d.warnings;
  return j;
}

std::string DiffWorseLines(const DiffResult& d) {
  std::string out;
  for (const Comparison& c : d.comparisons) {
    if (c.verdict != "worse") continue;
    out += "worse: " + ScopeLabel(c) + " " + c.metric + ": " + SideText(c, c.a) + " -> " + SideText(c, c.b) +
           ", change " + ChangeText(c) + ", p = " + PValue(c.p) + "\n";
  }
  return out;
}

std::string DiffToText(const DiffResult& d) {
  std::string out = "armfault diff: " + SideLine("A", d.a) + "\n";
  out += "               " + SideLine("B", d.b) + "\n";
  out += DiffCampaignLine(d) + "; " + OptionsLine(d.options) + "\n\n";
  std::vector<std::vector<std::string>> rows = {{"scope", "metric", "A", "B", "change [95% CI]", "p", "verdict"}};
  for (const Comparison& c : d.comparisons) {
    rows.push_back({ScopeLabel(c), c.metric, SideText(c, c.a), SideText(c, c.b), ChangeText(c), PValue(c.p),
                    VerdictText(c)});
  }
  std::vector<size_t> width(rows[0].size(), 0);
  for (const auto& r : rows) {
    for (size_t i = 0; i < r.size(); ++i) width[i] = std::max(width[i], r[i].size());
  }
  for (const auto& r : rows) {
    std::string line;
    for (size_t i = 0; i < r.size(); ++i) {
      line += r[i];
      if (i + 1 < r.size()) line += std::string(width[i] - r[i].size() + 2, ' ');
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += line + "\n";
  }
  if (!d.groups_only_in_a.empty() || !d.groups_only_in_b.empty()) out += "\n";
  for (const std::string& g : d.groups_only_in_a) out += "only in A: " + GroupLabel(g) + "\n";
  for (const std::string& g : d.groups_only_in_b) out += "only in B: " + GroupLabel(g) + "\n";
  const std::string worse = DiffWorseLines(d);
  out += "\n" + worse;
  out += std::to_string(d.comparisons.size()) + " comparisons: " + std::to_string(d.Count("better")) + " better, " +
         std::to_string(d.Count("worse")) + " worse, " + std::to_string(d.Count("same")) + " same, " +
         std::to_string(d.Count("inconclusive")) + " inconclusive, " + std::to_string(d.Count("n/a")) + " n/a\n";
  return out;
}

std::string DiffToMarkdown(const DiffResult& d) {
  std::string out = "# armfault diff\n\n";
  out += "- " + Cell(SideLine("A", d.a)) + "\n";
  out += "- " + Cell(SideLine("B", d.b)) + "\n";
  out += "- " + Cell(DiffCampaignLine(d)) + "\n";
  out += "- " + OptionsLine(d.options) + "; two-sided Fisher exact test for rates (Newcombe 95 % interval of the "
         "change), Mann-Whitney U for latency (median shift)\n\n";
  out += "| scope | metric | A | B | change [95% CI] | p | test | verdict |\n";
  out += "|---|---|---|---|---|---|---|---|\n";
  for (const Comparison& c : d.comparisons) {
    std::string verdict = VerdictText(c);
    if (c.verdict == "worse") verdict = "**worse**";
    out += "| " + Cell(ScopeLabel(c)) + " | " + c.metric + " | " + SideText(c, c.a) + " | " + SideText(c, c.b) + " | " +
           ChangeText(c) + " | " + PValue(c.p) + " | " + (c.test.empty() ? "-" : c.test) + " | " + verdict + " |\n";
  }
  if (!d.groups_only_in_a.empty() || !d.groups_only_in_b.empty()) {
    out += "\nGroups in one directory only (not compared):\n\n";
    for (const std::string& g : d.groups_only_in_a) out += "- only in A: " + Cell(GroupLabel(g)) + "\n";
    for (const std::string& g : d.groups_only_in_b) out += "- only in B: " + Cell(GroupLabel(g)) + "\n";
  }
  if (!d.warnings.empty()) {
    out += "\nWarnings:\n\n";
    for (const std::string& w : d.warnings) out += "- " + Cell(w) + "\n";
  }
  out += "\n" + std::to_string(d.comparisons.size()) + " comparisons: " + std::to_string(d.Count("better")) +
         " better, " + std::to_string(d.Count("worse")) + " worse, " + std::to_string(d.Count("same")) + " same, " +
         std::to_string(d.Count("inconclusive")) + " inconclusive, " + std::to_string(d.Count("n/a")) + " n/a.\n";
  return out;
}

}  // namespace armfault
