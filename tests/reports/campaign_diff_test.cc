#include "reports/campaign_diff.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/base/json_input.h"

namespace armfault {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;

const char kKt[] = "kt_degradation";
const char kKt07[] = "kt_degradation kt_factor=0.7 joint=3";
const char kKt05[] = "kt_degradation kt_factor=0.5 joint=3";
const char kBrake[] = "brake_lock drag_fraction=1 joint=3";

// ---------------------------------------------------------------- statistics

TEST(FisherExactTest, TeaTastingTableGivesTheKnownTwoSidedP) {
  // Fisher's lady tasting tea, [[3, 1], [1, 3]]: p = 17/35 = 0.4857.
  EXPECT_NEAR(FisherExactTwoSided(3, 4, 1, 4), 17.0 / 35.0, 1e-12);
  EXPECT_NEAR(FisherExactTwoSided(1, 4, 3, 4), 17.0 / 35.0, 1e-12);
}

TEST(FisherExactTest, MatchesKnownValuesAndLimits) {
  // [[1, 9], [11, 3]] (the textbook example, R: fisher.test gives p = 0.002759).
  EXPECT_NEAR(FisherExactTwoSided(1, 10, 11, 14), 0.0027594561852200836, 1e-12);
  EXPECT_NEAR(FisherExactTwoSided(100, 100, 90, 100), 0.0015420521254357006, 1e-12);
  EXPECT_NEAR(FisherExactTwoSided(40, 40, 20, 40), 7.798257540483748e-08, 1e-15);
  EXPECT_DOUBLE_EQ(FisherExactTwoSided(5, 10, 5, 10), 1.0);
  EXPECT_DOUBLE_EQ(FisherExactTwoSided(0, 7, 0, 9), 1.0);
  EXPECT_DOUBLE_EQ(FisherExactTwoSided(7, 7, 9, 9), 1.0);
  // Large tables stay finite and sensible (log-gamma terms, renormalised).
  const double p = FisherExactTwoSided(500000, 1000000, 501000, 1000000);
  EXPECT_GT(p, 0.0);
  EXPECT_LT(p, 0.2);
  EXPECT_THROW(FisherExactTwoSided(1, 0, 0, 1), std::invalid_argument);
  EXPECT_THROW(FisherExactTwoSided(3, 2, 0, 1), std::invalid_argument);
}

// Brute force: every table's probability from integer binomial coefficients (exact below
// 2^53 for these sizes), summed over the tables no more probable than the observed one; an
// independent route to Boost.Math's hypergeometric.
double BruteForceFisher(long s_a, long n_a, long s_b, long n_b) {
  auto choose = [](long n, long k) {
    double c = 1;
    for (long i = 1; i <= k; ++i) c = c * static_cast<double>(n - k + i) / static_cast<double>(i);
    return std::round(c);
  };
  const long k = s_a + s_b;
  const double observed = choose(n_a, s_a) * choose(n_b, s_b);
  double tail = 0, total = 0;
  for (long x = std::max(0L, k - n_b); x <= std::min(n_a, k); ++x) {
    const double w = choose(n_a, x) * choose(n_b, k - x);
    total += w;
    if (w <= observed * (1 + 1e-7)) tail += w;
  }
  return tail / total;
}

TEST(FisherExactTest, MatchesBruteForceOnEverySmallTable) {
  int tables = 0;
  for (long n_a = 1; n_a <= 12; ++n_a) {
    for (long n_b = 1; n_b <= 12; ++n_b) {
      for (long s_a = 0; s_a <= n_a; ++s_a) {
        for (long s_b = 0; s_b <= n_b; ++s_b) {
          ASSERT_NEAR(FisherExactTwoSided(s_a, n_a, s_b, n_b), BruteForceFisher(s_a, n_a, s_b, n_b), 1e-13)
              << s_a << "/" << n_a << " against " << s_b << "/" << n_b;
          ++tables;
        }
      }
    }
  }
  EXPECT_EQ(tables, 8100);  // (sum of n + 1 for n = 1 .. 12)^2 = 90^2: every table seen
}

// Larger tables: every table's log-probability from log-gamma terms, summed over the whole
// support in log space (the pass over all tables that the tails and Boost's cdf replace).
TEST(FisherExactTest, MatchesAFullPassOverLargerTables) {
  auto log_choose = [](long n, long k) { return std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0); };
  auto full_pass = [&](long s_a, long n_a, long s_b, long n_b) {
    const long k = s_a + s_b;
    const double observed = log_choose(n_a, s_a) + log_choose(n_b, s_b);
    double tail = 0, total = 0;
    for (long x = std::max(0L, k - n_b); x <= std::min(n_a, k); ++x) {
      const double v = log_choose(n_a, x) + log_choose(n_b, k - x);
      total += std::exp(v - observed);
      if (v <= observed + std::log1p(1e-7)) tail += std::exp(v - observed);
    }
    return tail / total;
  };
  std::mt19937 rng(8);
  for (int i = 0; i < 300; ++i) {
    const long n_a = std::uniform_int_distribution<long>(1, 400)(rng), n_b = std::uniform_int_distribution<long>(1, 400)(rng);
    const long s_a = std::uniform_int_distribution<long>(0, n_a)(rng);
    // B's rate near A's, so that p spans 1e-10 .. 1.
    const double rate = std::min(1.0, std::max(0.0, static_cast<double>(s_a) / n_a + std::normal_distribution<double>(0, 0.1)(rng)));
    const long s_b = std::lround(rate * n_b);
    const double want = full_pass(s_a, n_a, s_b, n_b);
    ASSERT_NEAR(FisherExactTwoSided(s_a, n_a, s_b, n_b), want, 1e-9 * want + 1e-300)
        << s_a << "/" << n_a << " against " << s_b << "/" << n_b;
  }
}

TEST(NewcombeTest, MatchesNewcombe1998Example) {
  // Newcombe (1998), 56/70 against 48/80: difference 0.2, hybrid score interval
  // 0.0524 to 0.3339. Here B = 56/70, A = 48/80 (change = B - A).
  const DifferenceInterval d = NewcombeDifference(48, 80, 56, 70);
  EXPECT_NEAR(d.difference, 0.2, 1e-12);
  EXPECT_NEAR(d.low, 0.0524, 5e-5);
  EXPECT_NEAR(d.high, 0.3339, 5e-5);
  const DifferenceInterval same = NewcombeDifference(10, 10, 10, 10);
  EXPECT_DOUBLE_EQ(same.difference, 0.0);
  EXPECT_LT(same.low, 0.0);
  EXPECT_NEAR(same.high, 1.0 - Wilson(10, 10).low, 1e-15);
}

TEST(MannWhitneyTest, ExactForSmallSamplesWithoutTies) {
  // {1, 2, 3} against {4, 5, 6}: every B above every A, U_B = 9; exactly 1 of the C(6, 3) = 20
  // orderings is as extreme on each side, so p = 2/20.
  const MannWhitneyResult r = MannWhitney({1, 2, 3}, {4, 5, 6});
  EXPECT_TRUE(r.exact);
  EXPECT_DOUBLE_EQ(r.u_b, 9.0);
  EXPECT_NEAR(r.p, 0.1, 1e-12);
  // R's ?wilcox.test example (x = A, y = B): W = U_A = 35, one-sided p 0.1272, two-sided 0.2544.
  const std::vector<double> x = {0.80, 0.83, 1.89, 1.04, 1.45, 1.38, 1.91, 1.64, 0.73, 1.46};
  const std::vector<double> y = {1.15, 0.88, 0.90, 0.74, 1.21};
  const MannWhitneyResult e = MannWhitney(x, y);
  EXPECT_TRUE(e.exact);
  EXPECT_DOUBLE_EQ(e.u_b, 15.0);
  EXPECT_NEAR(e.p, 0.2544122544122544, 1e-12);
  EXPECT_NEAR(MannWhitney(y, x).p, e.p, 1e-12);
}

// Brute force: every way of choosing which m of the m + n ranks are A's, each equally likely
// under the null; p = 2 min(P(U <= u), P(U >= u)), capped at 1.
double BruteForceMannWhitneyP(size_t m, size_t n, double u_b) {
  const size_t total = m + n;
  double le = 0, ge = 0, all = 0;
  for (unsigned mask = 0; mask < (1u << total); ++mask) {
    if (static_cast<size_t>(__builtin_popcount(mask)) != m) continue;  // bit r set: rank r is an A
    double u = 0;  // pairs (a, b) with b above a
    for (size_t r = 0; r < total; ++r) {
      if (!(mask >> r & 1u)) continue;
      for (size_t q = r + 1; q < total; ++q) u += (mask >> q & 1u) ? 0 : 1;
    }
    all += 1;
    le += u <= u_b + 1e-9;
    ge += u >= u_b - 1e-9;
  }
  return std::min(1.0, 2 * std::min(le, ge) / all);
}

TEST(MannWhitneyTest, ExactMatchesBruteForceEnumeration) {
  std::mt19937 rng(27);
  std::uniform_real_distribution<double> value(0, 1);
  for (size_t m = 1; m <= 6; ++m) {
    for (size_t n = 1; n <= 6; ++n) {
      for (int trial = 0; trial < 3; ++trial) {
        std::vector<double> a(m), b(n);
        for (double& x : a) x = value(rng);
        for (double& x : b) x = value(rng) + 0.3 * trial;  // from no shift to a clear one
        const MannWhitneyResult r = MannWhitney(a, b);
        ASSERT_TRUE(r.exact);
        ASSERT_NEAR(r.p, BruteForceMannWhitneyP(m, n, r.u_b), 1e-12) << m << " against " << n << ", U_B " << r.u_b;
      }
    }
  }
}

TEST(MannWhitneyTest, NormalApproximationWithTiesMatchesAHandComputation) {
  // A = {1, 2, 2, 3}, B = {2, 3, 4, 4, 5}. Sorted: 1a 2a 2a 2b 3a 3b 4b 4b 5b; mid-ranks
  // 1, 3, 3, 3, 5.5, 5.5, 7.5, 7.5, 9. R_B = 3 + 5.5 + 7.5 + 7.5 + 9 = 32.5, U_B = 32.5 - 15
  // = 17.5; mean 4 * 5 / 2 = 10. Ties t = 3, 2, 2: sum(t^3 - t) = 24 + 6 + 6 = 36;
  // Var = 20 / 12 * (10 - 36 / 72) = 15.8333. z = (7.5 - 0.5) / 3.97911 = 1.759186,
  // p = 2 (1 - Phi(z)) = 0.078546 (R: wilcox.test gives W = 2.5, p-value = 0.07855).
  const MannWhitneyResult r = MannWhitney({1, 2, 2, 3}, {2, 3, 4, 4, 5});
  EXPECT_FALSE(r.exact);
  EXPECT_DOUBLE_EQ(r.u_b, 17.5);
  EXPECT_NEAR(r.z, 1.759186414825121, 1e-9);
  EXPECT_NEAR(r.p, 0.0785458509511907, 1e-9);
  // The mirror image gives the opposite z and the same p.
  const MannWhitneyResult m = MannWhitney({2, 3, 4, 4, 5}, {1, 2, 2, 3});
  EXPECT_NEAR(m.z, -r.z, 1e-12);
  EXPECT_NEAR(m.p, r.p, 1e-12);
  // All values tied: no evidence either way.
  EXPECT_DOUBLE_EQ(MannWhitney({1, 1}, {1, 1, 1}).p, 1.0);
  EXPECT_THROW(MannWhitney({}, {1}), std::invalid_argument);
}

TEST(MannWhitneyTest, LargeSamplesUseTheNormalApproximation) {
  std::vector<double> a, b;
  for (int i = 0; i < 60; ++i) {
    a.push_back(i);
    b.push_back(i + 0.5);
  }
  const MannWhitneyResult r = MannWhitney(a, b);
  EXPECT_FALSE(r.exact);
  EXPECT_DOUBLE_EQ(r.u_b, 60.0 * 61 / 2);  // b_i beats a_0 .. a_i
  EXPECT_GT(r.p, 0.5);
}

TEST(MedianTest, AsTheSummaryDefinesIt) {
  EXPECT_FALSE(Median({}).has_value());
  EXPECT_DOUBLE_EQ(*Median({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(*Median({4, 1, 3, 2}), 2.5);
}

// ---------------------------------------------------------------- records

RunRecord Faulty(const std::string& id, const std::string& group, bool detected, double latency_s = 0.5,
                 bool isolated = true, bool before_onset = false) {
  RunRecord r;
  r.run_id = id;
  r.family = group.substr(0, group.find(' '));
  r.joint = 3;
  r.group = group;
  r.onset_s = 2.0;
  r.alarm_before_onset = before_onset;
  if (detected) {
    r.detected = true;
    r.latency_s = latency_s;
    r.detection_time_s = r.onset_s + latency_s;
    r.isolated_family = isolated ? r.family : "friction_increase";
    r.isolated_joint = 3;
  }
  return r;
}

RunRecord Healthy(const std::string& id, bool alarm) {
  RunRecord r;
  r.run_id = id;
  r.detected = alarm;
  return r;
}

// `n` runs of `group`, the first `detected` of them detected with latencies base + 0.01 i.
void AddGroup(CampaignResults* c, const std::string& group, int n, int detected, double base_latency = 0.5) {
  for (int i = 0; i < n; ++i) {
    c->records.Add(Faulty(group + "/r" + std::to_string(i), group, i < detected, base_latency + 0.01 * i));
  }
}

CampaignResults Baseline() {
  CampaignResults c;
  c.label = "a";
  c.campaign = {{"name", "ci"}, {"seed", 1}, {"monitor", {{"debounce_s", 0.5}}}};
  AddGroup(&c, kKt07, 40, 38);
  AddGroup(&c, kKt05, 40, 40);
  AddGroup(&c, kBrake, 20, 20, 0.2);
  for (int i = 0; i < 40; ++i) c.records.Add(Healthy("healthy/" + std::to_string(i), i == 0));
  return c;
}

const Comparison* Find(const DiffResult& d, const std::string& scope, const std::string& name,
                       const std::string& metric) {
  for (const Comparison& c : d.comparisons) {
    if (c.scope == scope && c.name == name && c.metric == metric) return &c;
  }
  return nullptr;
}

TEST(CampaignDiffTest, IdenticalCampaignsAreAllSame) {
  const CampaignResults a = Baseline();
  CampaignResults b = Baseline();
  b.label = "b";
  const DiffResult d = DiffCampaigns(a, b, DiffOptions{});
  EXPECT_TRUE(d.same_campaign);
  EXPECT_TRUE(d.campaign_differences.empty());
  EXPECT_FALSE(d.AnyWorse());
  EXPECT_EQ(d.common_groups, 4);
  EXPECT_TRUE(d.groups_only_in_a.empty());
  EXPECT_TRUE(d.groups_only_in_b.empty());
  ASSERT_FALSE(d.comparisons.empty());
  for (const Comparison& c : d.comparisons) {
    EXPECT_EQ(c.verdict, "same") << c.scope << " " << c.name << " " << c.metric;
    ASSERT_TRUE(c.p.has_value());
    EXPECT_DOUBLE_EQ(*c.p, 1.0);
    EXPECT_DOUBLE_EQ(*c.change, 0.0);
  }
  EXPECT_EQ(d.Count("same"), static_cast<long>(d.comparisons.size()));
  const std::string text = DiffToText(d);
  EXPECT_THAT(text, HasSubstr("same campaign \"ci\""));
  EXPECT_THAT(text, Not(HasSubstr("worse:")));
}

TEST(CampaignDiffTest, ScopesAndMetricsComeInTheDocumentedOrder) {
  const DiffResult d = DiffCampaigns(Baseline(), Baseline(), DiffOptions{});
  std::vector<std::string> rows;
  for (const Comparison& c : d.comparisons) rows.push_back(c.scope + "|" + c.name + "|" + c.metric);
  const std::vector<std::string> metrics = {"detection", "alarm_before_onset", "isolation", "latency"};
  std::vector<std::string> expected = {"overall||detection", "overall||false_alarm", "overall||alarm_before_onset",
                                       "overall||isolation", "overall||latency"};
  for (const char* family : {"brake_lock", "kt_degradation"}) {
    for (const std::string& m : metrics) expected.push_back(std::string("family|") + family + "|" + m);
  }
  // Groups sorted by key; the healthy group "" only repeats overall's false alarms: left out.
  for (const char* group : {kBrake, kKt05, kKt07}) {
    for (const std::string& m : metrics) expected.push_back(std::string("group|") + group + "|" + m);
  }
  EXPECT_EQ(rows, expected);
}

TEST(CampaignDiffTest, CountsFollowTheSummaryDefinitions) {
  const CampaignResults a = Baseline();
  const nlohmann::json summary = a.records.Build(Floors{}, nullptr, "test");
  const DiffResult d = DiffCampaigns(a, a, DiffOptions{});
  for (const char* metric : {"detection", "false_alarm", "isolation"}) {
    const Comparison* c = Find(d, "overall", "", metric);
    ASSERT_NE(c, nullptr) << metric;
    EXPECT_EQ(c->a.successes, summary["overall"][metric]["successes"].get<long>()) << metric;
    EXPECT_EQ(c->a.trials, summary["overall"][metric]["trials"].get<long>()) << metric;
  }
  const Comparison* latency = Find(d, "overall", "", "latency");
  EXPECT_DOUBLE_EQ(*latency->a.value, summary["overall"]["latency"]["median_s"].get<double>());
  EXPECT_EQ(latency->a.count, summary["overall"]["latency"]["count"].get<long>());
  const Comparison* before = Find(d, "family", kKt, "alarm_before_onset");
  EXPECT_EQ(before->a.trials, summary["per_family"][kKt]["alarm_before_onset_rate"]["trials"].get<long>());
}

// One denominator: runs whose fault could not act are out of diff's rates as out of
// summary.json's, and the header says how many each side left out.
TEST(CampaignDiffTest, NotExcitedRunsAreLeftOutAndCounted) {
  CampaignResults a = Baseline();
  for (int i = 0; i < 3; ++i) {
    RunRecord r = Faulty("still/r" + std::to_string(i), kKt07, false);
    r.not_excited_reason = "joint 3 was asked to move 0 rad after the onset";
    a.records.Add(r);
  }
  const DiffResult d = DiffCampaigns(a, Baseline(), DiffOptions{});
  EXPECT_EQ(d.a.not_excited, 3);
  EXPECT_EQ(d.b.not_excited, 0);
  EXPECT_EQ(Find(d, "overall", "", "detection")->a.trials, 100);  // 40 + 40 + 20, the 3 left out
  EXPECT_EQ(Find(d, "group", kKt07, "detection")->verdict, "same");
  EXPECT_THAT(DiffToText(d), HasSubstr("(campaign \"ci\", 143 runs, 0 failed, 3 not excited, left out)"));
  EXPECT_EQ(DiffToJson(d)["a"]["not_excited"], 3);
}

// "same" is a claim the samples must be able to back: 2/2 -> 0/2 (p = 0.33, and no outcome of
// 2 runs a side could reach p < 0.05) is inconclusive, as is a material change the runs cannot
// confirm (4/4 -> 2/4); identical groups large enough to show a change stay "same".
TEST(CampaignDiffTest, SamplesThatCannotShowAChangeAreInconclusive) {
  EXPECT_NEAR(SmallestFisherP(2, 2), 1.0 / 3, 1e-12);
  EXPECT_NEAR(SmallestFisherP(4, 4), 2.0 / 70, 1e-12);
  EXPECT_NEAR(SmallestMannWhitneyP(3, 3), 0.1, 1e-12);
  EXPECT_NEAR(SmallestMannWhitneyP(4, 4), 2.0 / 70, 1e-12);
  CampaignResults a, b;
  a.campaign = b.campaign = {{"name", "ci"}};
  AddGroup(&a, kKt07, 2, 2);
  AddGroup(&b, kKt07, 2, 0);
  AddGroup(&a, kKt05, 4, 4);
  AddGroup(&b, kKt05, 4, 2);
  AddGroup(&a, kBrake, 4, 4, 0.2);
  AddGroup(&b, kBrake, 4, 4, 0.2);
  const DiffResult d = DiffCampaigns(a, b, DiffOptions{});
  const Comparison* two = Find(d, "group", kKt07, "detection");
  EXPECT_NEAR(*two->p, 1.0 / 3, 1e-9);
  EXPECT_EQ(two->verdict, "inconclusive");
  EXPECT_EQ(Find(d, "group", kKt05, "detection")->verdict, "inconclusive");  // -0.5, p = 0.43
  EXPECT_EQ(Find(d, "group", kBrake, "detection")->verdict, "same");        // 4/4 both; 4 a side can show a change
  EXPECT_EQ(Find(d, "group", kBrake, "latency")->verdict, "same");
  EXPECT_EQ(Find(d, "group", kKt05, "latency")->verdict, "inconclusive");  // 4 against 2 latencies: p >= 0.133
  EXPECT_FALSE(d.AnyWorse());  // inconclusive never fails the gate
  EXPECT_THAT(DiffToText(d), HasSubstr(" inconclusive, "));
  EXPECT_EQ(DiffToJson(d)["counts"]["inconclusive"], d.Count("inconclusive"));
  // A larger tolerance is the material change when it exceeds 0.1.
  DiffOptions wide;
  wide.rate_tolerance = 0.6;
  EXPECT_EQ(Find(DiffCampaigns(a, b, wide), "group", kKt05, "detection")->verdict, "same");
}

TEST(CampaignDiffTest, AWorseCandidateIsWorseAndNamed) {
  const CampaignResults a = Baseline();
  CampaignResults b;
  b.label = "b";
  b.campaign = a.campaign;
  AddGroup(&b, kKt07, 40, 10);  // detection 38/40 -> 10/40
  AddGroup(&b, kKt05, 40, 40);
  AddGroup(&b, kBrake, 20, 20, 0.2);
  for (int i = 0; i < 40; ++i) b.records.Add(Healthy("healthy/" + std::to_string(i), i == 0));
  const DiffResult d = DiffCampaigns(a, b, DiffOptions{});
  EXPECT_TRUE(d.AnyWorse());
  const Comparison* g = Find(d, "group", kKt07, "detection");
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(g->verdict, "worse");
  EXPECT_TRUE(g->significant);
  EXPECT_NEAR(*g->change, 10.0 / 40 - 38.0 / 40, 1e-12);
  EXPECT_LT(*g->ci_high, 0.0);
  EXPECT_EQ(g->test, "fisher_exact");
  EXPECT_EQ(Find(d, "overall", "", "detection")->verdict, "worse");
  EXPECT_EQ(Find(d, "group", kKt05, "detection")->verdict, "same");
  const std::string worse = DiffWorseLines(d);
  EXPECT_THAT(worse, HasSubstr("worse: overall detection: 0.980 (98/100) -> 0.700 (70/100)"));
  EXPECT_THAT(worse, HasSubstr(std::string("worse: ") + kKt07 + " detection: 0.950 (38/40) -> 0.250 (10/40)"));
  EXPECT_THAT(DiffToText(d), HasSubstr(worse));
  // The other way round detection is better (and latency worse: the 28 runs detected again
  // have the longer latencies 0.60 .. 0.87 s of this construction).
  const DiffResult r = DiffCampaigns(b, a, DiffOptions{});
  EXPECT_EQ(Find(r, "group", kKt07, "detection")->verdict, "better");
  EXPECT_EQ(Find(r, "overall", "", "detection")->verdict, "better");
  for (const Comparison& c : r.comparisons) {
    if (c.verdict == "worse") {
      EXPECT_EQ(c.metric, "latency") << c.scope << " " << c.name;
    }
  }
  EXPECT_EQ(Find(r, "group", kKt07, "latency")->verdict, "worse");
}

TEST(CampaignDiffTest, ToleranceSuppressesASmallSignificantWorsening) {
  CampaignResults a, b;
  a.label = "a";
  b.label = "b";
  AddGroup(&a, kKt07, 100, 100);
  AddGroup(&b, kKt07, 100, 90);  // -0.10, Fisher p = 0.0015
  DiffOptions o;
  const DiffResult strict = DiffCampaigns(a, b, o);
  EXPECT_EQ(Find(strict, "group", kKt07, "detection")->verdict, "worse");
  o.rate_tolerance = 0.15;
  const DiffResult tolerant = DiffCampaigns(a, b, o);
  const Comparison* c = Find(tolerant, "group", kKt07, "detection");
  EXPECT_TRUE(c->significant);
  EXPECT_EQ(c->verdict, "same");
  EXPECT_FALSE(tolerant.AnyWorse());
  EXPECT_THAT(DiffToText(tolerant), HasSubstr("same (within tolerance)"));
  o.rate_tolerance = 0.05;
  EXPECT_TRUE(DiffCampaigns(a, b, o).AnyWorse());
  // A stricter alpha makes it not significant at all.
  o.rate_tolerance = 0;
  o.alpha = 0.001;
  EXPECT_FALSE(DiffCampaigns(a, b, o).AnyWorse());
}

TEST(CampaignDiffTest, LatencyShiftIsTestedAndToleranceApplies) {
  CampaignResults a, b;
  AddGroup(&a, kKt07, 30, 30, 0.5);  // latencies 0.50 .. 0.79
  AddGroup(&b, kKt07, 30, 30, 0.8);  // latencies 0.80 .. 1.09
  DiffOptions o;
  const DiffResult d = DiffCampaigns(a, b, o);
  const Comparison* c = Find(d, "group", kKt07, "latency");
  ASSERT_NE(c, nullptr);
  EXPECT_FALSE(c->is_rate);
  EXPECT_EQ(c->test, "mann_whitney_exact");
  EXPECT_NEAR(*c->change, 0.3, 1e-9);
  EXPECT_DOUBLE_EQ(*c->u_b, 900.0);
  EXPECT_EQ(c->verdict, "worse");
  o.latency_tolerance_s = 0.5;
  EXPECT_EQ(Find(DiffCampaigns(a, b, o), "group", kKt07, "latency")->verdict, "same");
  EXPECT_EQ(Find(DiffCampaigns(b, a, DiffOptions{}), "group", kKt07, "latency")->verdict, "better");
}

TEST(CampaignDiffTest, UntestableComparisonsAreNotApplicable) {
  CampaignResults a, b;
  AddGroup(&a, kKt07, 10, 0);  // nothing detected: no isolation, no latency
  AddGroup(&b, kKt07, 10, 0);
  const DiffResult d = DiffCampaigns(a, b, DiffOptions{});
  EXPECT_EQ(Find(d, "group", kKt07, "isolation")->verdict, "n/a");
  EXPECT_FALSE(Find(d, "group", kKt07, "isolation")->p.has_value());
  EXPECT_EQ(Find(d, "group", kKt07, "latency")->verdict, "n/a");
  EXPECT_EQ(Find(d, "group", kKt07, "detection")->verdict, "same");
  EXPECT_EQ(Find(d, "overall", "", "false_alarm"), nullptr);  // no healthy runs on either side
}

TEST(CampaignDiffTest, GroupsInOneDirectoryOnlyAreListedNotCompared) {
  CampaignResults a = Baseline();
  CampaignResults b;
  b.label = "b";
  b.campaign = {{"name", "ci-tuned"}, {"seed", 1}, {"monitor", {{"debounce_s", 0.3}}}};
  AddGroup(&b, kKt07, 40, 38);
  AddGroup(&b, "inverter_short kind=phase_phase resistance_ohm=0.1 joint=3", 10, 10);
  for (int i = 0; i < 40; ++i) b.records.Add(Healthy("healthy/" + std::to_string(i), i == 0));
  const DiffResult d = DiffCampaigns(a, b, DiffOptions{});
  EXPECT_FALSE(d.same_campaign);
  EXPECT_THAT(d.campaign_differences, ElementsAre("monitor", "name"));
  EXPECT_EQ(d.common_groups, 2);  // kt 0.7 and the healthy runs
  EXPECT_THAT(d.groups_only_in_a, ElementsAre(kBrake, kKt05));
  EXPECT_THAT(d.groups_only_in_b, ElementsAre("inverter_short kind=phase_phase resistance_ohm=0.1 joint=3"));
  EXPECT_THAT(d.families_only_in_a, ElementsAre("brake_lock"));
  EXPECT_THAT(d.families_only_in_b, ElementsAre("inverter_short"));
  EXPECT_EQ(Find(d, "group", kBrake, "detection"), nullptr);
  // Overall pools the common groups only: kt 0.7 (38/40) on both sides.
  const Comparison* overall = Find(d, "overall", "", "detection");
  EXPECT_EQ(overall->a.trials, 40);
  EXPECT_EQ(overall->b.trials, 40);
  EXPECT_EQ(overall->verdict, "same");
  const std::string text = DiffToText(d);
  EXPECT_THAT(text, HasSubstr(std::string("only in A: ") + kBrake));
  EXPECT_THAT(text, HasSubstr("only in B: inverter_short kind=phase_phase resistance_ohm=0.1 joint=3"));
  EXPECT_THAT(text, HasSubstr("the campaigns differ in: monitor name; comparisons are by group key"));
  const nlohmann::json j = DiffToJson(d);
  EXPECT_EQ(j["only_in_a"]["groups"], nlohmann::json({kBrake, kKt05}));
  EXPECT_EQ(j["only_in_b"]["families"], nlohmann::json({"inverter_short"}));
  EXPECT_FALSE(d.warnings.empty());
}

TEST(CampaignDiffTest, OutputDoesNotDependOnRecordOrder) {
  std::vector<RunRecord> records;
  for (int i = 0; i < 30; ++i) records.push_back(Faulty("kt/" + std::to_string(i), kKt07, i % 3 != 0, 0.3 + 0.07 * (i % 7)));
  for (int i = 0; i < 10; ++i) records.push_back(Healthy("h/" + std::to_string(i), i == 4));
  CampaignResults a, b;
  for (const RunRecord& r : records) a.records.Add(r);
  std::mt19937 rng(7);
  std::shuffle(records.begin(), records.end(), rng);
  for (const RunRecord& r : records) b.records.Add(r);
  CampaignResults c = Baseline();
  EXPECT_EQ(DiffToJson(DiffCampaigns(a, c, DiffOptions{})).dump(), DiffToJson(DiffCampaigns(b, c, DiffOptions{})).dump());
}

TEST(CampaignDiffTest, JsonAndMarkdownCarryEveryComparison) {
  const DiffResult d = DiffCampaigns(Baseline(), Baseline(), DiffOptions{});
  const nlohmann::json j = DiffToJson(d);
  EXPECT_EQ(j["comparisons"].size(), d.comparisons.size());
  EXPECT_EQ(j["worse"], false);
  EXPECT_EQ(j["counts"]["same"].get<long>(), static_cast<long>(d.comparisons.size()));
  EXPECT_EQ(j["options"]["alpha"], 0.05);
  const nlohmann::json& first = j["comparisons"][0];
  EXPECT_EQ(first["scope"], "overall");
  EXPECT_EQ(first["metric"], "detection");
  EXPECT_EQ(first["better"], "higher");
  EXPECT_EQ(first["a"]["trials"], 100);
  EXPECT_EQ(first["test"], "fisher_exact");
  const std::string md = DiffToMarkdown(d);
  EXPECT_THAT(md, HasSubstr("| scope | metric | A | B | change [95% CI] | p | test | verdict |"));
  EXPECT_GE(std::count(md.begin(), md.end(), '\n'), static_cast<long>(d.comparisons.size()) + 2);
  EXPECT_THAT(md, HasSubstr(std::string("| ") + kKt07 + " | detection | 0.950 (38/40) | 0.950 (38/40) |"));
}

TEST(CampaignDiffTest, ReadCampaignResultsRejectsAMissingDirectory) {
  try {
    ReadCampaignResults("/no/such/armfault/dir");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("/no/such/armfault/dir: (document root): no such directory"));
  }
}

TEST(CampaignDiffTest, OptionsAreChecked) {
  DiffOptions o;
  o.alpha = 0;
  EXPECT_THROW(CheckDiffOptions(o), InputError);
  o.alpha = 0.05;
  o.rate_tolerance = -0.1;
  EXPECT_THROW(CheckDiffOptions(o), InputError);
  o.rate_tolerance = 0;
  o.latency_tolerance_s = -1;
  EXPECT_THROW(DiffCampaigns(CampaignResults{}, CampaignResults{}, o), InputError);
}

}  // namespace
}  // namespace armfault
