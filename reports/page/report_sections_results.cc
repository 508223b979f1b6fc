// The sections of the rates as scored (summary.json, results.jsonl): rates and floors, the confusion
// matrix, the runs scored wrong, latency distributions.
#include "reports/page/report_sections.h"

#include <algorithm>
#include <cmath>

#include "reports/page/report_common.h"
#include "reports/page/vega_plot.h"

namespace armfault::report {


namespace {

// The p-quantile of sorted values, interpolated linearly between ranks; NaN when there are none.
double Quantile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return std::nan("");
  const double h = (static_cast<double>(sorted.size()) - 1) * p;
  const size_t i = static_cast<size_t>(std::floor(h));
  const size_t j = std::min(i + 1, sorted.size() - 1);
  return sorted[i] + (h - static_cast<double>(i)) * (sorted[j] - sorted[i]);
}

}  // namespace

std::string SummarySection(const ReportData& d) {
  const json& s = d.summary;
  const json empty = json::object();
  const json& overall = Field(s, "overall") ? s["overall"] : empty;
  std::string o = "<section id=\"summary\"><h2>Rates and floors</h2>";
  const json& runs = Field(s, "runs") ? s["runs"] : empty;
  o += "<p>" + std::to_string(Count(runs, "total")) + " runs: " + std::to_string(Count(runs, "faulty")) +
       " faulty, " + std::to_string(Count(runs, "healthy")) + " healthy, " + std::to_string(Count(runs, "failed")) +
       " failed. Rates are measured values with their 95 % Wilson score interval [low, high] and "
       "(successes/trials).</p>";
  const json& latency = Field(overall, "latency") ? overall["latency"] : empty;
  const json& magerr = Field(overall, "magnitude_error") ? overall["magnitude_error"] : empty;
  std::vector<std::vector<std::string>> rows = {
      {"detection rate (detected faulty / faulty runs)", Escape(RateText(SummaryRate(Field(overall, "detection"))))},
      {"false-alarm rate (alarmed healthy / healthy runs)", Escape(RateText(SummaryRate(Field(overall, "false_alarm"))))},
      {"isolation accuracy (right family and joint / detected)", Escape(RateText(SummaryRate(Field(overall, "isolation"))))},
      {"alarm before onset (faulty runs)", Escape(RateText(SummaryRate(Field(overall, "alarm_before_onset_rate"))))},
      {"latency after onset: median / 95th percentile",
       Escape(SecondsText(Num(latency, "median_s")) + " / " + SecondsText(Num(latency, "p95_s")) + " (" +
              std::to_string(Count(latency, "count")) + " detected, " + std::to_string(Count(latency, "misses")) +
              " missed)")},
      {"magnitude error |estimate − true| / |true|: mean / max",
       Escape((Num(magerr, "mean") ? Pct(*Num(magerr, "mean")) : "–") + " / " +
              (Num(magerr, "max") ? Pct(*Num(magerr, "max")) : "–") + " (" + std::to_string(Count(magerr, "count")) +
              " runs)")}};
  // Tables side by side where they fit: plots, not tables, should fill the page.
  o += "<div class=\"tables\"><div><h3>Overall</h3>" + HtmlTable({"metric", "value"}, rows, "kv") + "</div>";

  // Floors with verdicts.
  o += "<div><h3>Floors</h3>";
  const json* floors = Field(s, "floors");
  if (floors == nullptr || !floors->is_array() || floors->empty()) {
    o += "<p>The campaign sets no floors.</p>";
  } else {
    std::vector<std::vector<std::string>> frows;
    for (const json& f : *floors) {
      const auto measured = Num(f, "measured");
      // The message (with the counts) is the row's tooltip: the columns say the rest.
      frows.push_back({"<span title=\"" + Escape(Str(f, "message")) + "\">" + Escape(Str(f, "name")) + "</span>",
                       Str(f, "kind") == "max" ? "≤" : "≥", Escape(Num(f, "bound") ? Fixed(*Num(f, "bound"), 3) : "–"),
                       Escape(measured ? Fixed(*measured, 3) : "nothing to measure"),
                       VerdictHtml(Field(f, "met") && f["met"].is_boolean() && f["met"].get<bool>())});
    }
    o += HtmlTable({"floor", "", "bound", "measured", "verdict"}, frows);
  }
  o += "</div></div>";

  // Per family.
  o += "<h3>Per family</h3>";
  const json* families = Field(s, "per_family");
  if (families == nullptr || !families->is_object() || families->empty()) {
    o += "<p class=\"missing\">No per-family rates: summary.json counts no completed faulty runs.</p>";
  } else {
    std::vector<std::vector<std::string>> prows;
    for (const auto& [family, m] : families->items()) {
      const json& lat = Field(m, "latency") ? m["latency"] : empty;
      prows.push_back({"<span class=\"swatch\" style=\"background:" + FamilyColor(family) + "\"></span>" + Escape(family),
                       std::to_string(Count(m, "faulty_runs")), Escape(RateText(SummaryRate(Field(m, "detection")))),
                       Escape(RateText(SummaryRate(Field(m, "isolation")))),
                       Escape(RateText(SummaryRate(Field(m, "alarm_before_onset_rate")))),
                       Escape(SecondsText(Num(lat, "median_s"))), Escape(SecondsText(Num(lat, "p95_s")))});
    }
    o += HtmlTable({"family", "runs", "detection", "isolation", "alarm before onset", "latency median", "latency p95"},
                   prows);
  }
  o += "<h3>What the numbers mean</h3><ul class=\"metrics\">";
  for (const auto& [name, sentence] : MetricDefinitions()) o += "<li><b>" + Escape(name) + "</b>: " + Escape(sentence) + "</li>";
  return o + "</ul></section>";
}

std::string ConfusionSection(const ReportData& d) {
  std::string o = "<section id=\"confusion\"><h2>Confusion matrix</h2>";
  const json* c = Field(d.summary, "confusion");
  const json* labels = c != nullptr ? Field(*c, "labels") : nullptr;
  const json* counts = c != nullptr ? Field(*c, "counts") : nullptr;
  if (labels == nullptr || counts == nullptr || !labels->is_array() || !counts->is_array()) {
    return o + "<p class=\"missing\">No confusion matrix: summary.json has none (an older or edited file); run the "
               "campaign again to rebuild it.</p></section>";
  }
  vega::HeatMap h;
  h.id = "confusion";
  h.title = "True class against the class the monitor isolated";
  h.caption = "Counts of runs; shade: share of the row. healthy = no alarm, unknown = alarm without a family.";
  h.row_axis = "true class";
  h.col_axis = "isolated as (cells: number of runs)";
  for (size_t k = 0; k < labels->size(); ++k) {
    const std::string label = (*labels)[k].is_string() ? (*labels)[k].get<std::string>() : (*labels)[k].dump();
    h.cols.push_back(label);
    // No run is truly "unknown": that row is always empty and left out.
    if (label == "unknown") continue;
    h.rows.push_back(label);
    std::vector<long> row;
    if (k < counts->size() && (*counts)[k].is_array()) {
      for (const json& n : (*counts)[k]) row.push_back(n.is_number() ? n.get<long>() : 0);
    }
    h.counts.push_back(row);
  }
  return o + "<div class=\"plots\">" + h.Render() + "</div></section>";
}

std::string WhySection(const ReportData& d) {
  std::string o = "<section id=\"why\"><h2>Runs scored wrong, and why</h2>";
  auto table = [](const std::vector<ReportData::ListedRun>& runs, long count, const char* what) {
    std::string t = "<p>" + std::to_string(count) + " " + what +
                    (count > static_cast<long>(runs.size()) ? " (the first " + std::to_string(runs.size()) + " listed)" : "") +
                    ". Replay one with <code>armfault trace campaign.json --run RUN_ID</code> in the output directory.</p>";
    t += "<table><tr><th>run</th><th>why</th></tr>";
    for (const auto& r : runs) t += "<tr><td><code>" + Escape(r.run_id) + "</code></td><td>" + Escape(r.reason) + "</td></tr>";
    return t + "</table>";
  };
  if (d.wrong_count == 0) {
    o += "<p>Every run was scored right: no miss, no wrong family or joint, no healthy run that alarmed.</p>";
  } else {
    o += table(d.wrong, d.wrong_count, "runs missed, isolated to the wrong family or joint, or healthy runs that alarmed");
  }
  o += "<h3>Runs whose fault could not act (not excited)</h3>";
  if (d.not_excited_count == 0) {
    o += "<p>None: every fault changed the hardware where a monitor could see it.</p>";
  } else {
    o += std::string("<p>") +
         (d.not_excited_included ? "The campaign sets include_not_excited: these runs are scored like any other."
                                 : "Left out of every rate (summary.json lists them under not_excited_runs).") +
         "</p>" + table(d.not_excited, d.not_excited_count, "runs not excited");
  }
  return o + "</section>";
}

std::string LatencyDistributionSection(const ReportData& d) {
  std::string o = "<section id=\"latency\"><h2>Latency distributions</h2>";
  if (d.latencies_s.empty() && d.misses.empty()) {
    return o + "<p class=\"missing\">No latencies: results.jsonl holds no completed faulty runs.</p></section>";
  }
  if (d.latencies_s.empty()) {
    long missed = 0;
    for (const auto& [family, n] : d.misses) missed += n;
    return o + "<p class=\"missing\">No latencies: none of the " + std::to_string(missed) +
           " faulty runs was detected.</p></section>";
  }
  std::vector<std::string> families;
  for (const auto& [family, v] : d.latencies_s) families.push_back(family);
  for (const auto& [family, n] : d.misses) {
    if (!d.latencies_s.count(family)) families.push_back(family);
  }
  std::sort(families.begin(), families.end());
  double lo = INFINITY, hi = 0;
  for (const auto& [family, v] : d.latencies_s) {
    for (double x : v) {
      if (x > 0) lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
  }
  const int height = 110 + 46 * static_cast<int>(families.size());
  vega::Plot plot("latency-distribution", "Time from onset to first alarm, detected faulty runs", kFullWidth, height);
  constexpr size_t kMaxDots = 400;
  plot.set_caption("Box: quartiles; thick line: median; whiskers: range; dots: runs (at most " +
                   std::to_string(kMaxDots) + " per family, evenly spread). Log scale.");
  plot.x().label = "latency after onset (s, log scale)";
  plot.x().log = true;
  // A detection at the onset tick has latency 0: it sits at the axis' left end.
  if (std::isfinite(lo)) plot.x().min = std::pow(10.0, std::floor(std::log10(std::min(lo, 0.5 * hi))));
  for (const std::string& f : families) {
    auto it = d.latencies_s.find(f);
    const size_t n = it == d.latencies_s.end() ? 0 : it->second.size();
    auto m = d.misses.find(f);
    plot.y().categories.push_back(f + " (" + std::to_string(n) + " detected, " +
                                  std::to_string(m == d.misses.end() ? 0 : m->second) + " missed)");
  }
  plot.y().reversed = true;  // first family at the top
  for (size_t k = 0; k < families.size(); ++k) {
    auto it = d.latencies_s.find(families[k]);
    if (it == d.latencies_s.end() || it->second.empty()) continue;
    // Sorted with their runs, which the dots name.
    const auto runs_it = d.latency_runs.find(families[k]);
    std::vector<size_t> order(it->second.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return it->second[a] < it->second[b]; });
    std::vector<double> v;
    for (size_t i : order) v.push_back(it->second[i]);
    const std::string color = FamilyColor(families[k]);
    const double y = static_cast<double>(k);
    const double q1 = Quantile(v, 0.25), q2 = Quantile(v, 0.5), q3 = Quantile(v, 0.75);
    const double floor_x = plot.x().min.value_or(1e-3);
    auto at = [&](double x) { return std::max(x, floor_x); };
    plot.Line("", {at(v.front()), at(v.back())}, {y, y}, vega::Stroke{color, 1.2, "", 0.8});
    plot.Rect(at(q1), at(q3), y - 0.28, y + 0.28, color, 0.22, color,
              families[k] + ": quartiles " + Fixed(q1, 3) + " to " + Fixed(q3, 3) + " s, median " + Fixed(q2, 3) + " s");
    plot.Line("", {at(q2), at(q2)}, {y - 0.3, y + 0.3}, vega::Stroke{color, 3, "", 1});
    std::vector<double> xs, ys;
    std::vector<std::string> tips;
    std::vector<vega::RunRef> runs;
    // At most kMaxDots dots per family (every k-th of the sorted latencies) keep a big campaign's page small.
    const size_t stride = (v.size() + kMaxDots - 1) / kMaxDots;
    for (size_t i = 0; i < v.size(); i += stride) {
      // Deterministic jitter (golden-ratio sequence) so equal latencies do not hide each other.
      const double jitter = (std::fmod(static_cast<double>(i / stride) * 0.6180339887, 1.0) - 0.5) * 0.4;
      xs.push_back(at(v[i]));
      ys.push_back(y + jitter);
      tips.push_back(Fixed(v[i], 3) + " s after onset");
      if (runs_it != d.latency_runs.end() && order[i] < runs_it->second.size()) {
        runs.push_back({runs_it->second[order[i]].first, families[k], runs_it->second[order[i]].second, std::nullopt, ""});
      }
    }
    if (runs.size() != xs.size()) runs.clear();
    plot.Points("", xs, ys, {}, {}, color, vega::Marker::kCircle, tips, 2.6, runs);
  }
  return o + "<div class=\"plots\">" + plot.Render() + "</div></section>";
}

}  // namespace armfault::report
