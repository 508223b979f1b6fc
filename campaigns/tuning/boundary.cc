#include "campaigns/tuning/boundary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include "campaigns/scoring/provenance.h"
#include "campaigns/running/runner.h"
#include "core/base/distributions.h"
#include "core/base/json_input.h"
#include "faults/fault.h"

namespace armfault {

namespace {

namespace fs = std::filesystem;

// Steps of the scans for a90, a90/95 and the interval: 2000 over the range in log severity,
// as PodFitJson.
constexpr int kScanSteps = 2000;

struct CellKey {
  size_t trajectory = 0, entry = 0;
  int joint = 0;
};

std::vector<CellKey> Cells(const CampaignSpec& c) {
  std::vector<CellKey> cells;
  for (size_t t = 0; t < c.trajectories.size(); ++t) {
    for (size_t e = 0; e < c.faults.size(); ++e) {
      for (int j : c.faults[e].joints) cells.push_back({t, e, j});
    }
  }
  return cells;
}

// The cell of a record (-1: none): from its trajectory, its run_id's "<family>#<entry>/" and its joint.
long CellOf(const CampaignSpec& c, const std::vector<CellKey>& cells, const RunRecord& r) {
  if (r.family.empty()) return -1;
  const std::string head = r.trajectory + "/" + r.family + "#";
  if (r.run_id.compare(0, head.size(), head) != 0) return -1;
  size_t end = head.size();
  while (end < r.run_id.size() && std::isdigit(static_cast<unsigned char>(r.run_id[end]))) ++end;
  if (end == head.size() || end >= r.run_id.size() || r.run_id[end] != '/') return -1;
  const size_t entry = std::stoul(r.run_id.substr(head.size(), end - head.size()));
  for (size_t k = 0; k < cells.size(); ++k) {
    if (c.trajectories[cells[k].trajectory].name == r.trajectory && cells[k].entry == entry && cells[k].joint == r.joint) {
      return static_cast<long>(k);
    }
  }
  return -1;
}

bool Scored(const CampaignSpec& c, const SearchEntryRange& range, const RunRecord& r) {
  return r.ok && r.injected() && (r.excited() || c.include_not_excited) && r.magnitude_key == range.key;
}

// The first severity in [lo, hi] (log-spaced scan) where `value` reaches `target`.
template <class F>
std::optional<double> FirstAt(double lo, double hi, double target, F&& value) {
  for (int i = 0; i <= kScanSteps; ++i) {
    const double s = std::exp(std::log(lo) + (std::log(hi) - std::log(lo)) * i / kScanSteps);
    if (value(s) >= target) return s;
  }
  return std::nullopt;
}

std::pair<double, double> SeverityRange(const SearchEntryRange& r) {
  const double a = FaultSeverity(r.key, r.low), b = FaultSeverity(r.key, r.high);
  return {std::min(a, b), std::max(a, b)};
}

// The range's end of largest (top) or smallest severity, on the lattice.
double EndMagnitude(const SearchEntryRange& r, bool top) {
  const bool low_is_top = FaultSeverity(r.key, r.low) > FaultSeverity(r.key, r.high);
  return SearchLatticeValue(r, (low_is_top == top) ? r.low : r.high);
}

nlohmann::json Optional(const std::optional<double>& x) { return x ? nlohmann::json(*x) : nlohmann::json(nullptr); }

}  // namespace

double OneSidedZ(double confidence) { return StandardNormalQuantile(confidence); }

CellEstimate EstimateCell(const SearchSpec& spec, const SearchEntryRange& range, const CellData& data) {
  CellEstimate est;
  if (data.magnitudes.empty()) return est;
  std::vector<double> severity;
  for (double m : data.magnitudes) severity.push_back(FaultSeverity(range.key, m));
  est.fit = FitPod(severity, data.detected);
  est.has_fit = est.fit.ok && est.fit.slope > 0;
  if (!est.has_fit) return est;
  const double lo = *std::min_element(severity.begin(), severity.end());
  const double hi = *std::max_element(severity.begin(), severity.end());
  const double z = OneSidedZ(spec.confidence);
  auto magnitude = [&](std::optional<double> s) -> std::optional<double> {
    if (!s) return std::nullopt;
    return FaultMagnitudeOfSeverity(range.key, *s);
  };
  est.a90 = magnitude(FirstAt(lo, hi, spec.target, [&](double s) { return est.fit.Probability(s); }));
  est.a90_95 = magnitude(FirstAt(lo, hi, spec.target, [&](double s) { return est.fit.Bound(s, -z); }));
  est.interval_low = magnitude(FirstAt(lo, hi, spec.target, [&](double s) { return est.fit.Bound(s, z); }));
  if (est.a90_95 && est.interval_low) est.width = std::fabs(*est.a90_95 - *est.interval_low);
  return est;
}

CellStep PlanCell(const SearchSpec& spec, const SearchEntryRange& range, const CellData& data) {
  CellStep step;
  const auto [sa, sb] = SeverityRange(range);
  const double xa = std::log(sa), xb = std::log(sb);
  const long left = spec.max_runs - data.runs;
  if (left <= 0) {
    step.status = "budget";
    const CellEstimate est = EstimateCell(spec, range, data);
    if (est.width && *est.width <= range.tolerance) step.status = "converged";
    return step;
  }
  const int size = static_cast<int>(std::min<long>(spec.batch, left));
  auto spread = [&](double lo, double hi) {
    for (int i = 0; i < size; ++i) {
      const double x = size == 1 ? 0.5 * (lo + hi) : lo + (hi - lo) * i / (size - 1);
      step.magnitudes.push_back(SearchLatticeValue(range, FaultMagnitudeOfSeverity(range.key, std::exp(x))));
    }
  };
  if (data.runs == 0) {  // the first batch spans the range
    spread(xa, xb);
    return step;
  }
  const long hits = std::count(data.detected.begin(), data.detected.end(), true);
  const long misses = static_cast<long>(data.detected.size()) - hits;
  if (hits == 0 || misses == 0) {
    // All missed (or all detected) so far: try the end of the range where that would change,
    // and stop when `batch` runs there agree too.
    const double end = EndMagnitude(range, hits == 0);
    const long at_end = std::count(data.magnitudes.begin(), data.magnitudes.end(), end);
    if (data.detected.empty() || at_end < spec.batch) {
      step.magnitudes.assign(static_cast<size_t>(size), end);
      return step;
    }
    step.status = hits == 0 ? "above_range" : "below_range";
    return step;
  }
  const CellEstimate est = EstimateCell(spec, range, data);
  if (est.width && *est.width <= range.tolerance) {
    step.status = "converged";
    return step;
  }
  // Where the next runs tell most. While every detected run is more severe than every missed
  // one (complete separation: the fit's slope, and so its band, is undetermined), bisection:
  // the whole batch inside the gap between them.
  double max_miss = xa, min_hit = xb;
  for (size_t i = 0; i < data.magnitudes.size(); ++i) {
    const double x = std::log(FaultSeverity(range.key, data.magnitudes[i]));
    if (data.detected[i]) min_hit = std::min(min_hit, x);
    else max_miss = std::max(max_miss, x);
  }
  const double span = xb - xa;
  if (max_miss < min_hit) {
    for (int i = 0; i < size; ++i) {
      const double x = max_miss + (min_hit - max_miss) * (i + 1) / (size + 1);
      step.magnitudes.push_back(SearchLatticeValue(range, FaultMagnitudeOfSeverity(range.key, std::exp(x))));
    }
    return step;
  }
  double lo = std::min(max_miss, min_hit), hi = std::max(max_miss, min_hit);
  if (est.has_fit) {
    // Where the fit rises from 30 % to 98 %: the runs there pin down both its level and its
    // slope near the target, and so its lower bound (runs where it is 0 or 1 tell little).
    const PodFit& f = est.fit;
    auto x_at = [&](double p) { return (std::log(p / (1 - p)) - f.intercept) / f.slope; };
    lo = x_at(0.3);
    hi = x_at(std::max(0.98, spec.target + 0.5 * (1 - spec.target)));
  }
  lo = std::clamp(lo, xa, xb);
  hi = std::clamp(hi, xa, xb);
  if (hi - lo < 0.02 * span) {  // never a single point: widen to 2 % of the range
    const double mid = 0.5 * (lo + hi);
    lo = std::max(xa, mid - 0.01 * span);
    hi = std::min(xb, lo + 0.02 * span);
    lo = std::max(xa, hi - 0.02 * span);
  }
  spread(lo, hi);
  return step;
}

nlohmann::json BoundaryReport(const CampaignSpec& c, const std::vector<RunRecord>& records,
                              const std::vector<std::string>& statuses, int batches) {
  const std::vector<CellKey> cells = Cells(c);
  std::vector<CellData> data(cells.size());
  for (const RunRecord& r : records) {
    const long k = CellOf(c, cells, r);
    if (k < 0) continue;
    CellData& d = data[static_cast<size_t>(k)];
    ++d.runs;
    if (!Scored(c, c.search.entries[cells[static_cast<size_t>(k)].entry], r)) continue;
    d.magnitudes.push_back(r.magnitude);
    d.detected.push_back(r.detected);
  }
  const double z = OneSidedZ(c.search.confidence);
  nlohmann::json out = nlohmann::json::array();
  long total = 0;
  for (size_t k = 0; k < cells.size(); ++k) {
    const CellKey& key = cells[k];
    const SearchEntryRange& range = c.search.entries[key.entry];
    const CellData& d = data[k];
    total += d.runs;
    const CellEstimate est = EstimateCell(c.search, range, d);
    std::string status = k < statuses.size() ? statuses[k] : "";
    if (status.empty()) status = est.width && *est.width <= range.tolerance ? "converged" : "not_converged";
    std::string reason;
    if (status == "converged") {
      reason = "the interval of a90 is at most the tolerance wide";
    } else if (status == "budget") {
      reason = "max_runs used before the interval of a90 narrowed to the tolerance";
    } else if (status == "above_range") {
      reason = "no run detected, " + std::to_string(c.search.batch) + " or more of them at the top of the range: the boundary lies above it";
    } else if (status == "below_range") {
      reason = "every run detected, " + std::to_string(c.search.batch) + " or more of them at the bottom of the range: the boundary lies below it";
    } else if (status == "stopped") {
      reason = "stopped after " + std::to_string(batches) + " batches (--max-batches); --resume continues";
    } else {
      reason = "the interval of a90 is wider than the tolerance";
    }
    nlohmann::json points = nlohmann::json::array();
    for (size_t i = 0; i < d.magnitudes.size(); ++i) points.push_back({d.magnitudes[i], d.detected[i]});
    nlohmann::json fit = {{"ok", est.has_fit}};
    if (est.has_fit) {
      std::vector<double> sev;
      for (double m : d.magnitudes) sev.push_back(FaultSeverity(range.key, m));
      const double lo = *std::min_element(sev.begin(), sev.end()), hi = *std::max_element(sev.begin(), sev.end());
      nlohmann::json curve = nlohmann::json::array();
      for (int i = 0; i <= 60; ++i) {
        const double s = std::exp(std::log(lo) + (std::log(hi) - std::log(lo)) * i / 60);
        curve.push_back({{"magnitude", FaultMagnitudeOfSeverity(range.key, s)}, {"pod", est.fit.Probability(s)},
                         {"low", est.fit.Bound(s, -z)}, {"high", est.fit.Bound(s, z)}});
      }
      fit["intercept"] = est.fit.intercept;
      fit["slope_per_log_severity"] = est.fit.slope;
      fit["curve"] = curve;
    } else if (!est.fit.ok && !d.magnitudes.empty()) {
      fit["reason"] = est.fit.reason.empty() ? "no rising fit" : est.fit.reason;
    } else {
      fit["reason"] = d.magnitudes.empty() ? "no scored runs" : "the fit does not rise with severity";
    }
    out.push_back({{"trajectory", c.trajectories[key.trajectory].name},
                   {"entry", key.entry},
                   {"family", c.faults[key.entry].family},
                   {"joint", key.joint},
                   {"magnitude_key", range.key},
                   {"range", {range.low, range.high}},
                   {"tolerance", range.tolerance},
                   {"status", status},
                   {"reason", reason},
                   {"runs", d.runs},
                   {"scored_runs", d.magnitudes.size()},
                   {"detected", std::count(d.detected.begin(), d.detected.end(), true)},
                   {"a90_95", Optional(est.a90_95)},
                   {"a90", Optional(est.a90)},
                   {"interval", est.interval_low && est.a90_95
                                    ? nlohmann::json::array({std::min(*est.interval_low, *est.a90_95),
                                                             std::max(*est.interval_low, *est.a90_95)})
                                    : nlohmann::json(nullptr)},
                   {"width", Optional(est.width)},
                   {"points", points},
                   {"fit", fit}});
  }
  return {{"armfault_version", ARMFAULT_VERSION},
          {"campaign", c.name},
          {"campaign_hash", CampaignHash(c.resolved)},
          {"target", c.search.target},
          {"confidence", c.search.confidence},
          {"batch", c.search.batch},
          {"max_runs", c.search.max_runs},
          {"batches", batches},
          {"runs", total},
          {"model", "logistic in log(severity), Firth; boundary = a90/95, where the one-sided lower confidence "
                    "bound of the detection probability reaches the target"},
          {"cells", out}};
}

std::string BoundaryTable(const nlohmann::json& report) {
  auto num = [](const nlohmann::json& x) -> std::string {
    if (x.is_null()) return "-";
    char b[32];
    std::snprintf(b, sizeof b, "%.4f", x.get<double>());
    return b;
  };
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-14s %-20s %5s %-16s %8s %8s %19s %5s  %s\n", "trajectory", "family", "joint",
                "magnitude", "a90/95", "a90", "interval", "runs", "status");
  out += line;
  for (const nlohmann::json& c : report["cells"]) {
    const std::string interval =
        c["interval"].is_null() ? "-" : "[" + num(c["interval"][0]) + ", " + num(c["interval"][1]) + "]";
    std::snprintf(line, sizeof line, "%-14s %-20s %5d %-16s %8s %8s %19s %5ld  %s\n",
                  c["trajectory"].get<std::string>().c_str(), c["family"].get<std::string>().c_str(),
                  c["joint"].get<int>(), c["magnitude_key"].get<std::string>().c_str(), num(c["a90_95"]).c_str(),
                  num(c["a90"]).c_str(), interval.c_str(), c["runs"].get<long>(), c["status"].get<std::string>().c_str());
    out += line;
  }
  return out;
}

BoundaryResult RunBoundary(const Campaign& campaign, const BoundaryOptions& o) {
  if (!campaign.search.present) {
    throw InputError(campaign.source, "/search",
                     "missing: the campaign has no \"search\" block to tell what to search (docs/campaign-format.md, "
                     "\"Boundary search\")");
  }
  const fs::path dir(o.output_dir);
  fs::create_directories(dir);
  const fs::path campaign_path = dir / "campaign.json", results_path = dir / "results.jsonl",
                 decisions_path = dir / "decisions.jsonl", boundary_path = dir / "boundary.json";
  // The resolved campaign read once more (as every later batch's is), without runs: what a
  // directory to resume must hold apart from its runs.
  nlohmann::json base = CampaignFromJson(campaign.resolved, campaign.source, campaign.base_dir).resolved;
  base["search"].erase("runs");
  BoundaryResult out;
  std::vector<RunRecord> records;
  if (o.resume && fs::exists(campaign_path) && fs::exists(results_path)) {
    nlohmann::json file = ReadJsonFile(campaign_path.string());
    bool same = file.is_object() && file.value("armfault_version", "") == ARMFAULT_VERSION && file.contains("campaign") &&
                file["campaign"].is_object() && file["campaign"].contains("search") && file["campaign"]["search"].is_object();
    if (same) {
      file["campaign"]["search"].erase("runs");
      same = file["campaign"] == base;
    }
    if (!same) {
      throw InputError(campaign_path.string(), "",
                       "--resume: this directory holds another campaign or search; run it without --resume, or choose "
                       "another output directory");
    }
    records = CompleteRunRecords(results_path);
  } else {
    for (const fs::path& p : {results_path, decisions_path, boundary_path, campaign_path}) fs::remove(p);
  }

  const std::vector<CellKey> cells = Cells(campaign);
  std::vector<std::string> status(cells.size());
  std::vector<SearchRun> runs;
  std::map<std::tuple<size_t, size_t, int>, long> numbers;
  std::optional<Campaign> current;
  auto campaign_with = [&](const std::vector<SearchRun>& list) {
    nlohmann::json resolved = base;
    nlohmann::json array = nlohmann::json::array();
    for (const SearchRun& r : list) {
      array.push_back({{"trajectory", campaign.trajectories[r.trajectory].name},
                       {"entry", r.entry},
                       {"joint", r.joint},
                       {"magnitude", r.magnitude}});
    }
    resolved["search"]["runs"] = array;
    return CampaignFromJson(resolved, campaign.source, campaign.base_dir);
  };
  while (true) {
    // Each cell's runs so far (all of them have records: every earlier batch finished).
    std::vector<CellData> data(cells.size());
    for (size_t k = 0; k < runs.size(); ++k) {
      const SearchRun& run = runs[k];
      const RunRecord& r = records[k];
      const long cell = CellOf(campaign, cells, r);
      if (cell < 0) continue;
      CellData& d = data[static_cast<size_t>(cell)];
      ++d.runs;
      if (!Scored(campaign, campaign.search.entries[run.entry], r)) continue;
      d.magnitudes.push_back(r.magnitude);
      d.detected.push_back(r.detected);
    }
    std::vector<SearchRun> next = runs;
    std::vector<std::string> planned_status = status;
    for (size_t k = 0; k < cells.size(); ++k) {
      if (!status[k].empty()) continue;
      const CellStep step = PlanCell(campaign.search, campaign.search.entries[cells[k].entry], data[k]);
      if (step.magnitudes.empty()) {
        planned_status[k] = step.status;
        continue;
      }
      for (double m : step.magnitudes) {
        SearchRun r;
        r.trajectory = cells[k].trajectory;
        r.entry = cells[k].entry;
        r.joint = cells[k].joint;
        r.magnitude = m;
        next.push_back(r);
      }
    }
    status = planned_status;
    if (next.size() == runs.size()) break;  // every cell has stopped
    if (o.max_batches > 0 && out.batches >= o.max_batches) {
      out.stopped = true;
      for (std::string& s : status) {
        if (s.empty()) s = "stopped";
      }
      break;
    }
    for (size_t k = runs.size(); k < next.size(); ++k) {
      next[k].number = numbers[{next[k].trajectory, next[k].entry, next[k].joint}]++;
    }
    current.emplace(campaign_with(next));
    bool covered = records.size() >= next.size();
    for (size_t k = runs.size(); covered && k < next.size(); ++k) {
      covered = records[k].case_index == static_cast<long>(k) && records[k].run_id == SearchRunId(*current, next[k]);
    }
    if (covered) {
      out.resumed += static_cast<long>(next.size() - runs.size());
    } else {
      // campaign.json lists the batch before it runs: what is written is always a case of it.
      WriteAtomically(campaign_path, CampaignFileJson(*current, ShardSpec()).dump(2) + "\n");
      RunnerOptions ro;
      ro.output_dir = o.output_dir;
      ro.threads = o.threads;
      ro.resume = true;
      ro.stop = o.stop;
      const RunnerResult r = RunCampaign(*current, ro);
      out.resumed += r.resumed - static_cast<long>(runs.size());
      out.interrupted = r.interrupted;
      records = CompleteRunRecords(results_path);
      if (r.interrupted) {
        out.runs = static_cast<long>(records.size());
        return out;
      }
    }
    runs = std::move(next);
    ++out.batches;
    if (o.log) {
      long active = 0;
      for (const std::string& s : status) active += s.empty() ? 1 : 0;
      o.log("batch " + std::to_string(out.batches) + ": " + std::to_string(runs.size()) + " runs, " +
            std::to_string(active) + " of " + std::to_string(cells.size()) + " cells searching");
    }
  }
  if (!current) current.emplace(campaign_with(runs));
  // A directory holding more than this search's runs (planned by a stopped search with a
  // smaller --max-batches, say) keeps exactly them.
  if (records.size() != runs.size() || !fs::exists(campaign_path) ||
      ReadJsonFile(campaign_path.string()) != CampaignFileJson(*current, ShardSpec())) {
    WriteAtomically(campaign_path, CampaignFileJson(*current, ShardSpec()).dump(2) + "\n");
    RunnerOptions ro;
    ro.output_dir = o.output_dir;
    ro.threads = o.threads;
    ro.resume = true;
    RunCampaign(*current, ro);
    records = CompleteRunRecords(results_path);
  }
  for (const RunRecord& r : records) out.failed += r.ok ? 0 : 1;
  out.runs = static_cast<long>(records.size());
  out.report = BoundaryReport(*current, records, status, out.batches);
  out.report["stopped"] = out.stopped;
  WriteAtomically(boundary_path, out.report.dump(2) + "\n");
  return out;
}

}  // namespace armfault
