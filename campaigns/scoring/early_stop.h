// Sequential early stop for a campaign's floors (`armfault run --early-stop`).
//
// The runs go in an order that sweeps the campaign's case space evenly (EarlyStopOrder), and
// after each run, in that order, every floor not yet decided is judged on the runs so far: the
// probability that the *whole* campaign meets it, P_met, from a beta-binomial prediction of the
// runs of its scope still to come (Jeffreys prior on the rate; the remaining trials are the
// scope's remaining cases times the share of its cases so far that were trials). A floor is
// decided met when P_met >= confidence, missed when P_met <= 1 - confidence, and in either case
// only if the runs so far already say the same (their rate on that side of the bound) and it
// has at least `min_trials` trials, or when its scope has no case left (then P_met is 0 or 1).
// A decision is final. A case is run only while a floor whose scope holds it is undecided; when
// every floor is decided the campaign stops and the cases not run are saved.
//
// Everything is decided in the order of the runs, never of their finishing, so the outcome
// (which runs, their records) is the same for any thread count.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "campaigns/spec/campaign.h"
#include "campaigns/scoring/campaign_summary.h"
#include "campaigns/scoring/run_record.h"

namespace armfault {

struct EarlyStopOptions {
  double confidence = 0.99;  // in (0.5, 1)
  long min_trials = 10;
  nlohmann::json ToJson() const;
};

// A bijection of [0, count): k -> (step k + offset) mod count, step ~ 0.618 count and coprime
// with it, offset from the campaign's seed: consecutive runs land far apart in the mixed-radix
// case space, so every trajectory, family, magnitude and the healthy runs come up in proportion.
class EarlyStopOrder {
 public:
  EarlyStopOrder(long count, unsigned long long seed);
  long CaseIndex(long k) const;
  long count() const { return count_; }

 private:
  long count_, step_, offset_;
};

// P(the campaign's final rate (s + S) / (n + R) meets the bound), S ~ BetaBinomial(R, s + 1/2,
// n - s + 1/2); is_min: rate >= bound, else rate <= bound. R = 0: 1 or 0.
double PredictiveMet(long successes, long trials, long remaining, double bound, bool is_min);

struct FloorDecision {
  std::string name;  // as in summary.json's floors
  bool decided = false;
  bool met = false;
  double p_met = 0;        // at the decision (or now, while undecided)
  long decided_after = 0;  // runs made when it was decided
  long successes = 0, trials = 0;  // at the decision (or now)
};

class EarlyStop {
 public:
  // Counts the campaign's cases per scope (CaseAt over every case: time in the campaign's size,
  // memory flat). Throws InputError when the campaign has no floors (nothing to decide).
  EarlyStop(const Campaign& campaign, const EarlyStopOptions& options);
  // Whether a case (its fault family; "" healthy) is still needed by an undecided floor.
  bool Needed(const std::string& family) const;
  // A run made, in the order of the runs. Returns true when every floor is decided.
  bool Add(const RunRecord& record);
  bool AllDecided() const;
  long runs() const { return runs_; }
  const std::vector<FloorDecision>& floors() const { return decisions_; }
  // early_stop.json: options, runs made, cases, saved, decided, and the floors.
  nlohmann::json ToJson(long cases) const;

 private:
  struct Scope {
    std::string family;  // "" with healthy == false: every faulty case
    bool healthy = false;
    long cases = 0, seen = 0;
    bool Holds(const std::string& f) const { return healthy ? f.empty() : !f.empty() && (family.empty() || f == family); }
  };
  const Campaign& campaign_;
  EarlyStopOptions options_;
  SummaryBuilder builder_;
  std::vector<FloorDecision> decisions_;
  std::vector<Scope> scopes_;  // one per floor, in Verdicts() order
  long runs_ = 0;
};

}  // namespace armfault
