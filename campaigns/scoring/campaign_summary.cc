#include "campaigns/scoring/campaign_summary.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <iterator>
#include <stdexcept>
#include <tuple>

#include "campaigns/scoring/provenance.h"
#include "core/base/distributions.h"
#include "core/base/quote.h"

namespace armfault {

namespace {

using internal::SummaryTally;

// The two-sided 95 % normal quantile, 1.959963984540054.
const double kWilsonZ = StandardNormalQuantile(0.975);
constexpr size_t kMaxListedFailures = 100;
const char* const kHealthyLabel = "healthy";
const char* const kUnknownLabel = "unknown";
const char* const kCompoundFamily = "compound";  // compound runs: in no per_family entry


nlohmann::json StrOrNull(const std::string& s) { return s.empty() ? nlohmann::json(nullptr) : nlohmann::json(s); }

std::string Fixed3(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f", x);
  return buf;
}

void MergeInto(const SummaryTally& from, SummaryTally* into) {
  into->faulty += from.faulty;
  into->detected += from.detected;
  into->isolated += from.isolated;
  into->before_onset += from.before_onset;
  into->healthy += from.healthy;
  into->healthy_alarms += from.healthy_alarms;
  into->not_excited += from.not_excited;
  into->latencies_s.insert(into->latencies_s.end(), from.latencies_s.begin(), from.latencies_s.end());
  into->magnitude_errors.insert(into->magnitude_errors.end(), from.magnitude_errors.begin(),
                                from.magnitude_errors.end());
}

nlohmann::json RateJson(long successes, long trials) {
  const RateInterval w = Wilson(successes, trials);
  return {{"rate", w.rate}, {"low", w.low}, {"high", w.high}, {"successes", successes}, {"trials", trials}};
}

// Sorted copies: the statistics must not depend on the order the records arrived in.
nlohmann::json LatencyJson(const SummaryTally& t) {
  std::vector<double> v = t.latencies_s;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  nlohmann::json j = {{"count", n}, {"median_s", nullptr}, {"p95_s", nullptr}, {"misses", t.faulty - t.detected}};
  if (n > 0) {
    j["median_s"] = n % 2 == 1 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
    // Nearest rank, ceil(0.95 n) - 1, in integers so that no rounding can shift the rank.
    j["p95_s"] = v[(95 * n + 99) / 100 - 1];
  }
  return j;
}

nlohmann::json MagnitudeErrorJson(const SummaryTally& t) {
  std::vector<double> v = t.magnitude_errors;
  std::sort(v.begin(), v.end());
  nlohmann::json j = {{"count", v.size()}, {"mean", nullptr}, {"max", nullptr}};
  if (!v.empty()) {
    double sum = 0;
    for (double e : v) sum += e;
    j["mean"] = sum / static_cast<double>(v.size());
    j["max"] = v.back();
  }
  return j;
}

// The metrics every scope reports; the healthy part only where asked for.
nlohmann::json MetricsJson(const SummaryTally& t, bool with_healthy) {
  nlohmann::json j;
  j["runs"] = t.faulty + t.healthy;
  j["faulty_runs"] = t.faulty;
  j["not_excited"] = t.not_excited;
  j["detection"] = RateJson(t.detected, t.faulty);
  j["isolation"] = RateJson(t.isolated, t.detected);
  j["alarm_before_onset_rate"] = RateJson(t.before_onset, t.faulty);
  j["latency"] = LatencyJson(t);
  j["magnitude_error"] = MagnitudeErrorJson(t);
  if (with_healthy) {
    j["healthy_runs"] = t.healthy;
    j["false_alarm"] = RateJson(t.healthy_alarms, t.healthy);
  }
  return j;
}

nlohmann::json CompoundJson(const SummaryBuilder::CompoundTally& c) {
  nlohmann::json elements = nlohmann::json::array();
  for (const auto& [key, counts] : c.elements) {
    elements.push_back({{"position", key.first}, {"family", key.second}, {"isolated", RateJson(counts.first, counts.second)}});
  }
  return {{"runs", c.runs},
          {"detection", RateJson(c.detected, c.runs)},
          {"first_alarm_named_a_fault", RateJson(c.named, c.detected)},
          {"elements", std::move(elements)}};
}

// A verdict on successes / trials against a bound; `of_what` names the trials in the
// message, `none` says why there is nothing to measure when trials == 0.
FloorVerdict Check(const std::string& name, bool is_min, double bound, long successes, long trials,
                   const std::string& of_what, const std::string& none) {
  FloorVerdict v;
  v.name = name;
  v.kind = is_min ? "min" : "max";
  v.bound = bound;
  v.successes = successes;
  v.trials = trials;
  if (trials == 0) {
    v.met = false;
    v.message = name + ": " + none + ", nothing to measure (floor " + (is_min ? ">= " : "<= ") + Fixed3(bound) + ")";
    return v;
  }
  const double measured = static_cast<double>(successes) / static_cast<double>(trials);
  v.measured = measured;
  v.met = is_min ? measured >= bound : measured <= bound;
  const char* op = is_min ? (v.met ? ">=" : "<") : (v.met ? "<=" : ">");
  v.message = name + " " + Fixed3(measured) + " " + op + " " + Fixed3(bound) + " (" + std::to_string(successes) +
              " of " + std::to_string(trials) + " " + of_what + ")";
  return v;
}

void CheckSet(const FloorSet& floors, const std::string& prefix, const SummaryTally& t, bool family_scope,
              const std::string& no_runs, std::vector<FloorVerdict>* out) {
  if (floors.detection_rate) {
    out->push_back(Check(prefix + "detection_rate", true, *floors.detection_rate, t.detected, t.faulty, "runs",
                         no_runs));
  }
  if (floors.false_alarm_rate) {
    // A family has no healthy runs: its false alarms are the alarms before the fault's onset.
    out->push_back(family_scope ? Check(prefix + "false_alarm_rate", false, *floors.false_alarm_rate,
                                        t.before_onset, t.faulty, "runs alarmed before onset", no_runs)
                                : Check(prefix + "false_alarm_rate", false, *floors.false_alarm_rate,
                                        t.healthy_alarms, t.healthy, "healthy runs", "no healthy runs"));
  }
  if (floors.isolation_accuracy) {
    out->push_back(Check(prefix + "isolation_accuracy", true, *floors.isolation_accuracy, t.isolated, t.detected,
                         "detected runs", t.faulty == 0 ? no_runs : "no detected runs"));
  }
}

std::string XmlEscape(const std::string& s) { return EscapeMarkup(s, MarkupQuotes::kXml); }

// Counts one scored (ok, injected, excited or included) run into `t`.
void CountScored(const RunRecord& r, SummaryTally* tally) {
  SummaryTally& t = *tally;
  if (r.family.empty()) {
    ++t.healthy;
    if (r.detected) ++t.healthy_alarms;
    return;
  }
  ++t.faulty;
  if (r.alarm_before_onset) ++t.before_onset;
  if (!r.detected) return;
  ++t.detected;
  if (r.latency_s && std::isfinite(*r.latency_s)) t.latencies_s.push_back(*r.latency_s);
  if (!IsolatedRight(r)) return;
  ++t.isolated;
  if (r.magnitude_estimate && !r.magnitude_key.empty() && r.magnitude_name == r.magnitude_key && r.magnitude != 0) {
    const double error = std::abs(*r.magnitude_estimate - r.magnitude) / std::abs(r.magnitude);
    if (std::isfinite(error)) t.magnitude_errors.push_back(error);
  }
}

// A class of the joint confusion matrix: (family or "healthy"/"unknown", joint or 0).
using JointClass = std::pair<std::string, int>;

nlohmann::json JointClassJson(const JointClass& c) {
  return {{"family", c.first}, {"joint", c.second ? nlohmann::json(c.second) : nlohmann::json(nullptr)}};
}

}  // namespace

void internal::MergeTally(const SummaryTally& from, SummaryTally* into) { MergeInto(from, into); }

RateInterval Wilson(long successes, long trials) {
  if (trials < 0 || successes < 0 || successes > trials) {
    throw std::invalid_argument("Wilson: need 0 <= successes <= trials, got " + std::to_string(successes) + " of " +
                                std::to_string(trials));
  }
  if (trials == 0) return RateInterval{0, 0, 1};
  const double n = static_cast<double>(trials);
  const double p = static_cast<double>(successes) / n;
  const double z2 = kWilsonZ * kWilsonZ;
  const double denom = 1 + z2 / n;
  const double center = (p + z2 / (2 * n)) / denom;
  const double half = kWilsonZ * std::sqrt(p * (1 - p) / n + z2 / (4 * n * n)) / denom;
  RateInterval r;
  r.rate = p;
  // Exact ends at 0 and n, where rounding would otherwise leave 1e-17 outside [0, 1].
  r.low = successes == 0 ? 0.0 : std::max(0.0, center - half);
  r.high = successes == trials ? 1.0 : std::min(1.0, center + half);
  return r;
}

void SummaryBuilder::Add(const RunRecord& r) {
  if (!r.ok) {
    ++failed_runs_;
    // Keep the smallest ids so the listing does not depend on the order of arrival.
    failed_listed_.emplace(r.run_id, r.failure_reason);
    if (failed_listed_.size() > kMaxListedFailures) failed_listed_.erase(std::prev(failed_listed_.end()));
    // The lowest case number, then the smallest run_id: independent of the order of arrival.
    if (first_failure_.case_index < 0 ||
        std::tie(r.case_index, r.run_id) < std::tie(first_failure_.case_index, first_failure_.run_id)) {
      first_failure_ = {r.case_index, r.run_id, r.failure_reason};
    }
    return;
  }
  ++ok_runs_;
  for (const auto& [joint, seconds] : r.sensor_saturated_s) {
    SaturationTally& t = saturation_[joint];
    ++t.runs;
    t.longest_s = std::max(t.longest_s, seconds);
  }
  conditional_onset_runs_ += r.conditional_onset ? 1 : 0;
  compound_seen_ += r.is_compound() ? 1 : 0;
  if (!r.family.empty() && !r.injected()) {
    // Its onset condition never fired: no fault acted, so neither a detection nor a miss.
    ++not_injected_runs_;
    not_injected_listed_.emplace(r.run_id, r.not_injected_reason);
    if (not_injected_listed_.size() > kMaxListedFailures) not_injected_listed_.erase(std::prev(not_injected_listed_.end()));
    return;
  }
  if (!r.family.empty() && !r.excited()) {
    ++not_excited_runs_;
    not_excited_listed_.emplace(r.run_id, r.not_excited_reason);
    if (not_excited_listed_.size() > kMaxListedFailures) not_excited_listed_.erase(std::prev(not_excited_listed_.end()));
    TrajectoryCell& cell = by_trajectory_[{r.family, r.trajectory, r.group}];
    ++cell.tally.not_excited;
    if (cell.not_excited_reason.empty()) cell.not_excited_reason = r.not_excited_reason;
    if (!r.is_compound()) ++by_family_joint_[{r.family, r.joint}].not_excited;
    SummaryTally& t = cells_[{r.group, r.family}];
    ++t.not_excited;
    if (!t.has_descriptor || std::tie(r.joint, r.magnitude_key, r.magnitude) < std::tie(t.joint, t.magnitude_key, t.magnitude)) {
      t.has_descriptor = true;
      t.joint = r.joint;
      t.magnitude_key = r.magnitude_key;
      t.magnitude = r.magnitude;
    }
    if (!include_not_excited_) return;
  }
  {
    TrajectoryCell& cell = by_trajectory_[{r.family, r.trajectory, r.group}];
    SummaryTally& tt = cell.tally;
    bool wrong;
    if (r.family.empty()) {
      ++tt.healthy;
      tt.healthy_alarms += r.detected;
      wrong = r.detected;
    } else {
      ++tt.faulty;
      tt.before_onset += r.alarm_before_onset;
      tt.detected += r.detected;
      const bool isolated = IsolatedRight(r);
      tt.isolated += isolated;
      wrong = !isolated;
    }
    if (wrong && (cell.first_wrong_case < 0 || r.case_index < cell.first_wrong_case)) {
      cell.first_wrong_case = r.case_index;
      cell.first_wrong_run_id = r.run_id;
    }
  }
  SummaryTally& t = cells_[{r.group, r.family}];
  const auto descriptor = std::tie(r.joint, r.magnitude_key, r.magnitude);
  if (!t.has_descriptor || descriptor < std::tie(t.joint, t.magnitude_key, t.magnitude)) {
    t.has_descriptor = true;
    t.joint = r.joint;
    t.magnitude_key = r.magnitude_key;
    t.magnitude = r.magnitude;
  }

  if (r.is_compound()) {
    // Its own section; no row in the confusion matrix (its truth is no single family).
    for (CompoundTally* c : {&compound_, &compound_by_name_[r.fault.value("name", "")]}) {
      ++c->runs;
      c->detected += r.detected;
      c->named += IsolatedRight(r);
      for (size_t i = 0; i < r.compound.size(); ++i) {
        auto& e = c->elements[{i, r.compound[i].value("family", "")}];
        e.first += r.compound[i].value("isolated", false);
        ++e.second;
      }
    }
  } else {
    const std::string predicted =
        !r.detected ? kHealthyLabel : (r.isolated_family.empty() ? kUnknownLabel : r.isolated_family);
    ++confusion_[r.family.empty() ? kHealthyLabel : r.family][predicted];
    const JointClass truth = r.family.empty() ? JointClass{kHealthyLabel, 0} : JointClass{r.family, r.joint};
    const JointClass named = !r.detected ? JointClass{kHealthyLabel, 0} : JointClass{predicted, r.isolated_joint};
    ++joint_confusion_[truth][named];
  }

  CountScored(r, &t);
  if (r.is_compound()) return;  // no single joint: in no per-joint scope
  if (r.family.empty()) {
    // A false alarm counts against the joint its alarm named (0: none named).
    if (r.detected) ++healthy_alarms_by_joint_[r.isolated_joint];
    return;
  }
  CountScored(r, &by_family_joint_[{r.family, r.joint}]);
}

std::vector<FloorVerdict> SummaryBuilder::Verdicts(const Floors& floors) const {
  SummaryTally overall;
  std::map<std::string, SummaryTally> families;
  for (const auto& [key, t] : cells_) {
    MergeInto(t, &overall);
    if (!key.second.empty() && key.second != kCompoundFamily) MergeInto(t, &families[key.second]);
  }
  std::vector<FloorVerdict> out;
  CheckSet(floors.overall, "", overall, false, "no faulty runs", &out);
  for (const auto& [family, set] : floors.per_family) {
    auto it = families.find(family);
    const SummaryTally none;
    CheckSet(set, "per_family/" + family + "/", it == families.end() ? none : it->second, true,
             "no runs of family " + family, &out);
  }
  // Every run failed: there is nothing to measure because nothing ran to the end, not because the
  // campaign has no such runs. Said so, with the first failure, and the floor is not met.
  if (ok_runs_ == 0 && failed_runs_ > 0) {
    for (FloorVerdict& v : out) {
      v.met = false;
      v.message = v.name + ": all " + std::to_string(failed_runs_) + " runs failed, nothing to measure (floor " +
                  (v.kind == "min" ? ">= " : "<= ") + Fixed3(v.bound) + "); first failed " + FirstFailureText();
    }
  }
  return out;
}

long SummaryBuilder::healthy_runs() const {
  long n = 0;
  for (const auto& [key, t] : cells_) n += t.healthy;
  return n;
}

long SummaryBuilder::healthy_alarms() const {
  long n = 0;
  for (const auto& [key, t] : cells_) n += t.healthy_alarms;
  return n;
}

HealthyOperation HealthyOperationOf(const SummaryBuilder& builder, double duration_s, double set_for_per_hour) {
  HealthyOperation h;
  h.set_for_per_hour = set_for_per_hour;
  h.runs = builder.healthy_runs();
  h.false_alarms = builder.healthy_alarms();
  h.hours = static_cast<double>(h.runs) * duration_s / 3600.0;
  return h;
}

nlohmann::json HealthyOperation::ToJson() const {
  const bool any = hours > 0;
  nlohmann::json j = {{"healthy_runs", runs},
          {"false_alarms", false_alarms},
          {"hours", hours},
          {"per_hour", any ? nlohmann::json(static_cast<double>(false_alarms) / hours) : nlohmann::json(nullptr)},
          {"per_hour_upper_95", any ? nlohmann::json(PoissonUpperBound(false_alarms, 0.95) / hours) : nlohmann::json(nullptr)},
          {"counted",
           "healthy runs that alarmed, over the healthy runs' hours (each lasting the campaign's duration_s); upper "
           "bound one-sided 95 % (Poisson, chi-squared)"}};
  if (set_for_per_hour > 0) j["set_for_per_hour"] = set_for_per_hour;
  return j;
}

std::string HealthyOperation::Line() const {
  char buf[256];
  if (hours > 0) {
    std::snprintf(buf, sizeof buf,
                  "healthy operation: %ld runs, %.4g h, %ld false alarm%s: %.3g per hour (95 %% upper bound %.3g)", runs,
                  hours, false_alarms, false_alarms == 1 ? "" : "s", static_cast<double>(false_alarms) / hours,
                  PoissonUpperBound(false_alarms, 0.95) / hours);
    if (set_for_per_hour > 0) {
      const size_t n = std::strlen(buf);
      std::snprintf(buf + n, sizeof buf - n, ", set for %g per hour", set_for_per_hour);
    }
  } else {
    std::snprintf(buf, sizeof buf, "healthy operation: no healthy runs scored, no rate per hour");
  }
  return buf;
}

std::string SummaryBuilder::FirstFailureText() const {
  if (first_failure_.case_index < 0) return "";
  return "run " + first_failure_.run_id + ": " + first_failure_.reason;
}

nlohmann::json SummaryBuilder::Build(const Floors& floors, const nlohmann::json& campaign,
                                     const std::string& version) const {
  nlohmann::json j;
  j["armfault_version"] = version;
  j["campaign"] = campaign;
  // Which campaign these numbers are of: the report and the tuner refuse to mix campaigns.
  j["campaign_hash"] = campaign.is_null() ? nlohmann::json(nullptr) : nlohmann::json(CampaignHash(campaign));

  SummaryTally overall;
  std::map<std::string, SummaryTally> families;
  nlohmann::json groups = nlohmann::json::array();
  // cells_ is sorted by (group, family): the cells of one group are adjacent. A group
  // normally holds one family; if it holds several, its descriptors come from the first
  // faulty one.
  for (auto it = cells_.begin(); it != cells_.end();) {
    const std::string& group = it->first.first;
    SummaryTally merged;
    const std::pair<const std::pair<std::string, std::string>, SummaryTally>* described = nullptr;
    for (; it != cells_.end() && it->first.first == group; ++it) {
      MergeInto(it->second, &merged);
      MergeInto(it->second, &overall);
      if (!it->first.second.empty() && it->first.second != kCompoundFamily) MergeInto(it->second, &families[it->first.second]);
      if (described == nullptr || (described->first.second.empty() && !it->first.second.empty())) described = &*it;
    }
    const SummaryTally& d = described->second;
    nlohmann::json g;
    g["group"] = group;
    g["family"] = StrOrNull(described->first.second);
    g["joint"] = d.joint == 0 ? nlohmann::json(nullptr) : nlohmann::json(d.joint);
    g["magnitude_key"] = StrOrNull(d.magnitude_key);
    g["magnitude"] = d.magnitude_key.empty() ? nlohmann::json(nullptr) : nlohmann::json(d.magnitude);
    g.update(MetricsJson(merged, merged.healthy > 0));
    groups.push_back(std::move(g));
  }

  j["runs"] = {{"total", runs()},
               {"ok", ok_runs_},
               {"failed", failed_runs_},
               {"faulty", overall.faulty},
               {"healthy", overall.healthy},
               {"not_excited", not_excited_runs_}};
  j["overall"] = MetricsJson(overall, true);
  j["per_family"] = nlohmann::json::object();
  for (const auto& [family, t] : families) j["per_family"][family] = MetricsJson(t, false);
  j["groups"] = std::move(groups);

  // Labels: every family seen as a true or a predicted class, then the two fixed classes.
  std::set<std::string> names;
  for (const auto& [truth, row] : confusion_) {
    names.insert(truth);
    for (const auto& [predicted, count] : row) names.insert(predicted);
  }
  names.erase(kHealthyLabel);
  names.erase(kUnknownLabel);
  std::vector<std::string> labels(names.begin(), names.end());
  labels.push_back(kHealthyLabel);
  labels.push_back(kUnknownLabel);
  nlohmann::json counts = nlohmann::json::array();
  for (const std::string& truth : labels) {
    nlohmann::json row = nlohmann::json::array();
    auto r = confusion_.find(truth);
    for (const std::string& predicted : labels) {
      long n = 0;
      if (r != confusion_.end()) {
        auto c = r->second.find(predicted);
        if (c != r->second.end()) n = c->second;
      }
      row.push_back(n);
    }
    counts.push_back(std::move(row));
  }
  j["confusion"] = {{"labels", labels}, {"counts", std::move(counts)}};
  j["confusion_by_joint"] = JointConfusionJson();
  const auto [per_joint, per_family_joint] = PerJointJson();
  j["per_joint"] = per_joint;
  j["per_family_joint"] = per_family_joint;

  nlohmann::json verdicts = nlohmann::json::array();
  bool all_met = true;
  for (const FloorVerdict& v : Verdicts(floors)) {
    verdicts.push_back({{"name", v.name},
                        {"kind", v.kind},
                        {"bound", v.bound},
                        {"measured", v.measured ? nlohmann::json(*v.measured) : nlohmann::json(nullptr)},
                        {"met", v.met},
                        {"message", v.message}});
    all_met = all_met && v.met;
  }
  j["floors"] = std::move(verdicts);
  j["floors_met"] = all_met;

  nlohmann::json listed = nlohmann::json::array();
  for (const auto& [run_id, reason] : failed_listed_) listed.push_back({{"run_id", run_id}, {"reason", reason}});
  j["failed_runs"] = {{"count", failed_runs_},
                      {"truncated", failed_runs_ > static_cast<long>(failed_listed_.size())},
                      {"runs", std::move(listed)}};
  nlohmann::json not_excited = nlohmann::json::array();
  for (const auto& [run_id, reason] : not_excited_listed_) not_excited.push_back({{"run_id", run_id}, {"reason", reason}});
  j["not_excited_runs"] = {{"count", not_excited_runs_},
                           {"included", include_not_excited_},
                           {"truncated", not_excited_runs_ > static_cast<long>(not_excited_listed_.size())},
                           {"runs", std::move(not_excited)}};
  // Only for a campaign with compound faults, so other summaries are unchanged.
  if (compound_seen_ > 0) {
    nlohmann::json c = CompoundJson(compound_);
    c["per_name"] = nlohmann::json::object();
    for (const auto& [name, t] : compound_by_name_) c["per_name"][name] = CompoundJson(t);
    j["compound"] = std::move(c);
  }
  // Only for a campaign with conditional onsets, so other summaries are unchanged.
  if (conditional_onset_runs_ > 0) {
    nlohmann::json not_injected = nlohmann::json::array();
    for (const auto& [run_id, reason] : not_injected_listed_) not_injected.push_back({{"run_id", run_id}, {"reason", reason}});
    j["runs"]["not_injected"] = not_injected_runs_;
    j["not_injected_runs"] = {{"count", not_injected_runs_},
                              {"truncated", not_injected_runs_ > static_cast<long>(not_injected_listed_.size())},
                              {"runs", std::move(not_injected)}};
  }
  return j;
}

std::map<int, SummaryTally> SummaryBuilder::JointTallies() const {
  std::map<int, SummaryTally> joints;
  for (const auto& [key, t] : by_family_joint_) MergeInto(t, &joints[key.second]);
  long healthy = 0;
  for (const auto& [key, t] : cells_) healthy += key.second.empty() ? t.healthy : 0;
  for (const auto& [joint, alarms] : healthy_alarms_by_joint_) {
    if (joint > 0) joints[joint];  // a joint that only false-alarmed has a row too
  }
  for (auto& [joint, t] : joints) {
    t.healthy = healthy;
    const auto it = healthy_alarms_by_joint_.find(joint);
    t.healthy_alarms = it == healthy_alarms_by_joint_.end() ? 0 : it->second;
  }
  return joints;
}

std::pair<nlohmann::json, nlohmann::json> SummaryBuilder::PerJointJson() const {
  nlohmann::json per_joint = nlohmann::json::array();
  for (const auto& [joint, t] : JointTallies()) {
    nlohmann::json row = {{"joint", joint}};
    row.update(MetricsJson(t, false));
    row["runs"] = t.faulty;  // its faulty runs; the healthy runs are the campaign's
    row["healthy_runs"] = t.healthy;
    row["false_alarm"] = RateJson(t.healthy_alarms, t.healthy);
    per_joint.push_back(std::move(row));
  }
  nlohmann::json per_family_joint = nlohmann::json::array();
  for (const auto& [key, t] : by_family_joint_) {
    nlohmann::json row = {{"family", key.first}, {"joint", key.second}};
    row.update(MetricsJson(t, false));
    per_family_joint.push_back(std::move(row));
  }
  return {per_joint, per_family_joint};
}

nlohmann::json SummaryBuilder::JointConfusionJson() const {
  // Labels: every (family, joint) seen as a true or named class, sorted, then healthy and
  // unknown (always present), then any unknown family named on a joint.
  std::set<JointClass> seen;
  for (const auto& [truth, row] : joint_confusion_) {
    seen.insert(truth);
    for (const auto& [named, count] : row) seen.insert(named);
  }
  std::vector<JointClass> labels;
  for (const JointClass& c : seen) {
    if (c.first != kHealthyLabel && c.first != kUnknownLabel) labels.push_back(c);
  }
  labels.push_back({kHealthyLabel, 0});
  labels.push_back({kUnknownLabel, 0});
  for (const JointClass& c : seen) {
    if (c.first == kUnknownLabel && c.second != 0) labels.push_back(c);
  }
  nlohmann::json label_json = nlohmann::json::array(), counts = nlohmann::json::array();
  for (const JointClass& truth : labels) {
    label_json.push_back(JointClassJson(truth));
    nlohmann::json row = nlohmann::json::array();
    const auto r = joint_confusion_.find(truth);
    for (const JointClass& named : labels) {
      long n = 0;
      if (r != joint_confusion_.end()) {
        const auto c = r->second.find(named);
        if (c != r->second.end()) n = c->second;
      }
      row.push_back(n);
    }
    counts.push_back(std::move(row));
  }
  return {{"labels", std::move(label_json)}, {"counts", std::move(counts)}};
}

std::string JUnitXml(const std::string& campaign_name, const std::vector<FloorVerdict>& verdicts) {
  long failures = 0;
  for (const FloorVerdict& v : verdicts) failures += v.met ? 0 : 1;
  const std::string tests = std::to_string(verdicts.empty() ? 1 : verdicts.size());
  const std::string counts = " tests=\"" + tests + "\" failures=\"" + std::to_string(failures) + "\"";
  std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  xml += "<testsuites" + counts + ">\n";
  xml += "  <testsuite name=\"" + XmlEscape("armfault floors: " + campaign_name) + "\"" + counts + ">\n";
  if (verdicts.empty()) xml += "    <testcase classname=\"floors\" name=\"no floors\"/>\n";
  for (const FloorVerdict& v : verdicts) {
    xml += "    <testcase classname=\"floors\" name=\"" + XmlEscape(v.name) + "\"";
    if (v.met) {
      xml += "/>\n";
      continue;
    }
    xml += ">\n      <failure message=\"" + XmlEscape(v.message) + "\">" + XmlEscape(v.message) +
           "</failure>\n    </testcase>\n";
  }
  xml += "  </testsuite>\n</testsuites>\n";
  return xml;
}

std::string JUnitXml(const std::string& campaign_name, const SummaryBuilder& builder, const Floors& floors,
                     const std::string& campaign_json) {
  const std::vector<FloorVerdict> verdicts = builder.Verdicts(floors);
  // The floors suite as the plain writer makes it, without its closing tags.
  std::string floors_xml = JUnitXml(campaign_name, verdicts);
  floors_xml = floors_xml.substr(floors_xml.find("  <testsuite "));
  floors_xml = floors_xml.substr(0, floors_xml.rfind("</testsuites>"));
  long tests = verdicts.empty() ? 1 : static_cast<long>(verdicts.size()), failures = 0;
  for (const FloorVerdict& v : verdicts) failures += v.met ? 0 : 1;

  // Suites in family order, "healthy" last.
  std::map<std::string, std::vector<const std::pair<const SummaryBuilder::TrajectoryKey, SummaryBuilder::TrajectoryCell>*>> suites;
  for (const auto& item : builder.trajectory_cells()) suites[std::get<0>(item.first)].push_back(&item);
  std::string body;
  auto emit_suite = [&](const std::string& family) {
    auto it = suites.find(family);
    if (it == suites.end()) return;
    const std::string suite = family.empty() ? kHealthyLabel : family;
    auto floors_it = floors.per_family.find(family);
    const FloorSet& set = family.empty() || floors_it == floors.per_family.end() ? floors.overall : floors_it->second;
    std::string cases;
    long suite_failures = 0, suite_skipped = 0;
    for (const auto* item : it->second) {
      const auto& [key, cell] = *item;
      const SummaryTally& t = cell.tally;
      const std::string name = std::get<1>(key) + ": " + (family.empty() ? "healthy runs" : std::get<2>(key));
      std::vector<FloorVerdict> checks;
      if (family.empty()) {
        if (set.false_alarm_rate) {
          checks.push_back(Check("false_alarm_rate", false, *set.false_alarm_rate, t.healthy_alarms, t.healthy,
                                 "healthy runs", "no healthy runs"));
        }
      } else {
        CheckSet(set, "", t, !family.empty() && floors_it != floors.per_family.end(), "no faulty runs", &checks);
      }
      std::string counts = family.empty()
                               ? std::to_string(t.healthy) + " healthy runs, " + std::to_string(t.healthy_alarms) + " alarmed"
                               : std::to_string(t.faulty) + " runs, " + std::to_string(t.detected) + " detected, " +
                                     std::to_string(t.isolated) + " isolated (family and joint), " +
                                     std::to_string(t.before_onset) + " alarmed before the onset";
      if (t.not_excited > 0) {
        counts += "; " + std::to_string(t.not_excited) + " not excited" +
                  (builder.includes_not_excited() ? " (scored)" : " (left out)") + ", e.g. " + cell.not_excited_reason;
      }
      cases += "    <testcase classname=\"" + XmlEscape(suite) + "\" name=\"" + XmlEscape(name) + "\">\n";
      if (!family.empty() && t.faulty == 0 && t.not_excited > 0) {
        // Nothing here could be seen: skipped, not passed and not failed.
        ++suite_skipped;
        cases += "      <skipped message=\"" + XmlEscape("not excited: " + cell.not_excited_reason) + "\"/>\n";
      }
      cases += "      <system-out>" + XmlEscape(counts) + "</system-out>\n";
      for (const FloorVerdict& v : checks) {
        if (v.met || !v.measured) continue;  // a floor with nothing to measure here is not this case's
        ++suite_failures;
        std::string text = v.message + "; " + counts;
        if (cell.first_wrong_case >= 0) {
          text += "\nreplay the first wrong run, in the output directory: armfault trace " + campaign_json + " --run '" +
                  cell.first_wrong_run_id + "' -o trace.csv";
        }
        cases += "      <failure message=\"" + XmlEscape(v.message) + "\">" + XmlEscape(text) + "</failure>\n";
      }
      cases += "    </testcase>\n";
    }
    tests += static_cast<long>(it->second.size());
    failures += suite_failures;
    body += "  <testsuite name=\"" + XmlEscape(suite) + "\" tests=\"" + std::to_string(it->second.size()) +
            "\" failures=\"" + std::to_string(suite_failures) + "\"" +
            (suite_skipped > 0 ? " skipped=\"" + std::to_string(suite_skipped) + "\"" : std::string()) + ">\n" + cases + "  </testsuite>\n";
  };
  for (const auto& [family, cells] : suites) {
    if (!family.empty()) emit_suite(family);
  }
  emit_suite("");
  // Per joint and per family x joint: counts only (floors are overall and per family), so that
  // a CI page shows which joint the misses and false alarms are on.
  {
    auto latency = [](const SummaryTally& t) {
      if (t.latencies_s.empty()) return std::string();
      const nlohmann::json l = LatencyJson(t);
      char buf[64];
      std::snprintf(buf, sizeof buf, ", latency median %.3f s", l["median_s"].get<double>());
      return std::string(buf);
    };
    auto faulty_counts = [&](const SummaryTally& t) {
      std::string text = t.faulty == 0 && t.not_excited == 0 ? std::string("no faulty runs") : std::to_string(t.faulty) + " runs, " + std::to_string(t.detected) + " detected, " +
                         std::to_string(t.isolated) + " isolated (family and joint)" + latency(t);
      if (t.not_excited > 0) {
        text += "; " + std::to_string(t.not_excited) + " not excited" +
                (builder.includes_not_excited() ? " (scored)" : " (left out)");
      }
      return text;
    };
    std::string cases;
    long count = 0;
    for (const auto& [joint, t] : builder.JointTallies()) {
      const std::string text = faulty_counts(t) + "; false alarms naming joint " + std::to_string(joint) + ": " +
                               std::to_string(t.healthy_alarms) + " of " + std::to_string(t.healthy) + " healthy runs";
      cases += "    <testcase classname=\"per joint\" name=\"joint " + std::to_string(joint) + "\">\n      <system-out>" +
               XmlEscape(text) + "</system-out>\n    </testcase>\n";
      ++count;
    }
    for (const auto& [key, t] : builder.family_joint_cells()) {
      cases += "    <testcase classname=\"per joint\" name=\"" + XmlEscape(key.first + ": joint " + std::to_string(key.second)) +
               "\">\n      <system-out>" + XmlEscape(faulty_counts(t)) + "</system-out>\n    </testcase>\n";
      ++count;
    }
    if (count > 0) {
      body += "  <testsuite name=\"per joint\" tests=\"" + std::to_string(count) + "\" failures=\"0\">\n" + cases +
              "  </testsuite>\n";
      tests += count;
    }
  }
  // Failed runs: one failing case (a stable name, "every run completes") naming the first (its run_id and reason) and how to replay it.
  // Only when a run failed, so the junit.xml of a campaign without failures is unchanged.
  if (builder.failed_runs() > 0) {
    const SummaryBuilder::FirstFailure& first = builder.first_failure();
    const std::string count = std::to_string(builder.failed_runs()) + " of " + std::to_string(builder.runs()) + " runs failed";
    const std::string message = count + "; first failed " + builder.FirstFailureText();
    const std::string text = message + "\nevery failed run: failed_runs in summary.json" +
                             "\nreplay the first failed run, in the output directory: armfault trace " + campaign_json +
                             " --run '" + first.run_id + "' -o trace.csv";
    body += "  <testsuite name=\"failed runs\" tests=\"1\" failures=\"1\">\n"
            "    <testcase classname=\"failed runs\" name=\"every run completes\">\n"
            "      <failure message=\"" + XmlEscape(message) + "\">" + XmlEscape(text) + "</failure>\n"
            "    </testcase>\n  </testsuite>\n";
    ++tests;
    ++failures;
  }
  std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  xml += "<testsuites name=\"" + XmlEscape("armfault: " + campaign_name) + "\" tests=\"" + std::to_string(tests) +
         "\" failures=\"" + std::to_string(failures) + "\">\n";
  return xml + floors_xml + body + "</testsuites>\n";
}

}  // namespace armfault
