#include "campaigns/scoring/early_stop.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <boost/math/distributions/beta.hpp>

#include "core/base/json_input.h"

namespace armfault {

nlohmann::json EarlyStopOptions::ToJson() const {
  return {{"confidence", confidence}, {"min_trials", min_trials}, {"order", "golden-ratio stride"}};
}

EarlyStopOrder::EarlyStopOrder(long count, unsigned long long seed) : count_(count), step_(1), offset_(0) {
  if (count_ <= 1) return;
  step_ = std::max(1L, std::lround(0.6180339887498949 * static_cast<double>(count_)));
  while (std::gcd(step_, count_) != 1) ++step_;
  offset_ = static_cast<long>(seed % static_cast<unsigned long long>(count_));
}

long EarlyStopOrder::CaseIndex(long k) const {
  // (step k + offset) mod count without overflow for any count < 2^62.
  const __int128 v = static_cast<__int128>(step_) * k + offset_;
  return static_cast<long>(v % count_);
}

namespace {

double LogBeta(double a, double b) { return std::lgamma(a) + std::lgamma(b) - std::lgamma(a + b); }

// P(S >= t), S ~ BetaBinomial(n, a, b): summed term by term up to n = 5000 (Boost.Math has no
// beta-binomial), beyond from the beta distribution it tends to.
double BetaBinomialTail(long n, double a, double b, long t) {
  if (t <= 0) return 1.0;
  if (t > n) return 0.0;
  if (n > 5000) {
    // The beta-binomial's limit as n grows: S / n ~ Beta(a, b), the rate's posterior
    // (Boost.Math), continuity-corrected. A normal with S's mean and variance was off by up to
    // 0.08 here when few runs were seen (9 of 10, 5000 to come); this, by 0.0012.
    return boost::math::cdf(boost::math::complement(boost::math::beta_distribution<double>(a, b), (t - 0.5) / n));
  }
  const double base = -LogBeta(a, b) + std::lgamma(n + 1.0);
  double sum = 0;
  for (long k = t; k <= n; ++k) {
    sum += std::exp(base - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0) + LogBeta(k + a, n - k + b));
  }
  return std::min(1.0, sum);
}

}  // namespace

double PredictiveMet(long s, long n, long remaining, double bound, bool is_min) {
  const long total = n + remaining;
  if (total == 0) return 0.0;  // nothing to measure: not met, as the summary says
  // Final successes needed (min: s + S >= bound total) or allowed (max: s + S <= bound total).
  // A tolerance of 1e-9 so that exact ratios (0.8 x 40 = 32) fall on the summary's side.
  const double a = s + 0.5, b = n - s + 0.5;
  if (is_min) {
    const long need = static_cast<long>(std::ceil(bound * static_cast<double>(total) - 1e-9)) - s;
    return BetaBinomialTail(remaining, a, b, need);
  }
  const long allowed = static_cast<long>(std::floor(bound * static_cast<double>(total) + 1e-9)) - s;
  if (allowed < 0) return 0.0;
  return 1.0 - BetaBinomialTail(remaining, a, b, allowed + 1);
}

EarlyStop::EarlyStop(const Campaign& campaign, const EarlyStopOptions& options)
    : campaign_(campaign), options_(options), builder_(campaign.include_not_excited) {
  for (const FloorVerdict& v : builder_.Verdicts(campaign.floors)) {
    FloorDecision d;
    d.name = v.name;
    decisions_.push_back(d);
    Scope scope;
    // "false_alarm_rate" overall is of the healthy runs; every other floor of faulty runs
    // (a family's false alarms are its alarms before the onset).
    if (v.name == "false_alarm_rate") scope.healthy = true;
    const std::string prefix = "per_family/";
    if (v.name.compare(0, prefix.size(), prefix) == 0) {
      scope.family = v.name.substr(prefix.size(), v.name.rfind('/') - prefix.size());
    }
    scopes_.push_back(scope);
  }
  if (decisions_.empty()) {
    throw InputError(campaign.source, "/floors",
                     "--early-stop decides floors, and this campaign sets none: run it without --early-stop");
  }
  const long count = CaseCount(campaign);
  for (long k = 0; k < count; ++k) {
    const CaseSpec spec = CaseAt(campaign, k);
    const std::string family = spec.fault.is_null() ? "" : spec.fault.value("family", "");
    for (Scope& scope : scopes_) scope.cases += scope.Holds(family) ? 1 : 0;
  }
}

bool EarlyStop::Needed(const std::string& family) const {
  for (size_t f = 0; f < scopes_.size(); ++f) {
    if (!decisions_[f].decided && scopes_[f].Holds(family)) return true;
  }
  return false;
}

bool EarlyStop::AllDecided() const {
  return std::all_of(decisions_.begin(), decisions_.end(), [](const FloorDecision& d) { return d.decided; });
}

bool EarlyStop::Add(const RunRecord& record) {
  ++runs_;
  builder_.Add(record);
  for (Scope& scope : scopes_) scope.seen += scope.Holds(record.family) ? 1 : 0;
  const std::vector<FloorVerdict> verdicts = builder_.Verdicts(campaign_.floors);
  for (size_t f = 0; f < decisions_.size(); ++f) {
    FloorDecision& d = decisions_[f];
    if (d.decided) continue;
    const FloorVerdict& v = verdicts[f];
    const Scope& scope = scopes_[f];
    const long left = scope.cases - scope.seen;
    // The scope's remaining cases that will be trials, at the share of its cases so far.
    const long remaining =
        scope.seen == 0 ? left
                        : std::lround(static_cast<double>(left) * static_cast<double>(v.trials) / static_cast<double>(scope.seen));
    d.successes = v.successes;
    d.trials = v.trials;
    d.p_met = PredictiveMet(v.successes, v.trials, remaining, v.bound, v.kind == "min");
    const bool exhausted = left == 0;
    const bool enough = v.trials >= options_.min_trials;
    if (exhausted || (enough && d.p_met >= options_.confidence && v.met)) {
      d.decided = true;
      d.met = exhausted ? v.met : true;
    } else if (enough && d.p_met <= 1 - options_.confidence && !v.met) {
      d.decided = true;
      d.met = false;
    }
    if (d.decided) d.decided_after = runs_;
  }
  return AllDecided();
}

nlohmann::json EarlyStop::ToJson(long cases) const {
  nlohmann::json floors = nlohmann::json::array();
  for (const FloorDecision& d : decisions_) {
    floors.push_back({{"name", d.name},
                      {"decided", d.decided},
                      {"met", d.decided ? nlohmann::json(d.met) : nlohmann::json(nullptr)},
                      {"p_met", d.p_met},
                      {"decided_after_runs", d.decided ? nlohmann::json(d.decided_after) : nlohmann::json(nullptr)},
                      {"successes", d.successes},
                      {"trials", d.trials}});
  }
  return {{"options", options_.ToJson()}, {"runs", runs_},     {"cases", cases},
          {"saved", cases - runs_},      {"decided", AllDecided()}, {"floors", floors}};
}

}  // namespace armfault
