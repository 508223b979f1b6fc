// The sections of simulated runs: the thesis table 5-3 and one run over time.
#include "reports/page/report_sections.h"

#include <algorithm>
#include <cmath>

#include "reports/page/report_common.h"
#include "reports/page/vega_plot.h"

namespace armfault::report {


std::string ThesisSection(const ReportData& d) {
  std::string o = "<section id=\"thesis\"><h2>Efficiency against K_T factor (thesis table 5-3)</h2>";
  if (d.table_5_3.empty()) {
    if (d.thesis_source.rfind("not shown", 0) == 0) return o + "<p class=\"missing\">" + Escape(d.thesis_source) + ".</p></section>";
    return o + "<p class=\"missing\">No thesis results: " + Escape(d.thesis_source) + " holds no table_5_3 rows.</p></section>";
  }
  vega::Plot plot("thesis-table-5-3", "Top-joint efficiency (eq 5-5) as the torque constant degrades", kHalfWidth, 340);
  plot.set_caption("armfault: " + d.thesis_source + ". Degradation grows to the right.");
  plot.x().label = "K_T factor n (torque constant / nominal)";
  plot.x().reversed = true;
  plot.y().label = "efficiency η (%)";
  plot.y().min = 0;
  plot.y().max = 100;
  std::vector<double> xs, thesis, ours;
  std::vector<std::string> ttips, otips;
  std::vector<std::vector<std::string>> rows;
  for (const ThesisRow& r : d.table_5_3) {
    xs.push_back(r.factor);
    thesis.push_back(r.thesis_pct);
    ours.push_back(r.ok ? r.armfault_pct : std::nan(""));
    ttips.push_back("n = " + Fixed(r.factor, 2) + ": thesis " + Fixed(r.thesis_pct, 2) + " %");
    otips.push_back("n = " + Fixed(r.factor, 2) + ": armfault " + Fixed(r.armfault_pct, 2) + " % (" +
                    std::to_string(r.windows) + " windows)");
    rows.push_back({Fixed(r.factor, 2), Fixed(r.thesis_pct, 2), r.ok ? Fixed(r.armfault_pct, 2) : "failed",
                    Fixed(r.thesis_ratio, 3), Fixed(r.armfault_ratio, 3), std::to_string(r.windows)});
  }
  plot.Line("thesis (published)", xs, thesis, vega::Stroke{"#444", 2, "6 3", 1}, vega::Marker::kSquare);
  plot.Points("", xs, thesis, {}, {}, "#444", vega::Marker::kSquare, ttips, 3.5);
  plot.Line("armfault (simulated)", xs, ours, vega::Stroke{"#1f77b4", 2.2, "", 1}, vega::Marker::kCircle);
  plot.Points("", xs, ours, {}, {}, "#1f77b4", vega::Marker::kCircle, otips, 3.5);
  o += "<div class=\"plots\">" + plot.Render() + "<div class=\"side\">" +
       HtmlTable({"K_T factor", "thesis η (%)", "armfault η (%)", "thesis ratio", "armfault ratio", "windows"}, rows) +
       "<p>Ratio: relative to n = 1. Efficiency: Σ E_out / Σ E_mesh_in over the top joint's forward-flow windows "
       "(docs/monitor.md).</p></div></div>";
  return o + "</section>";
}

namespace {

// A run record's outcome in words, for the page.
std::string RecordText(const RunRecord& r) {
  if (!r.ok) return "failed: " + r.failure_reason;
  if (!r.detected) return "not detected";
  std::string s = "detected at " + Fixed(r.detection_time_s.value_or(0), 3) + " s";
  if (!r.isolated_family.empty()) s += ", isolated " + r.isolated_family + " on joint " + std::to_string(r.isolated_joint);
  if (r.magnitude_estimate) s += ", " + r.magnitude_name + " ≈ " + Fixed(*r.magnitude_estimate, 3);
  return s;
}

// The run every mark of a run's plots stands for (tooltip, click-to-copy).
vega::RunRef RefOf(const RunSeries& s) {
  const RunRecord& r = s.record;
  vega::RunRef ref{s.run_id, r.family, r.joint, std::nullopt, r.magnitude_key};
  if (!r.magnitude_key.empty()) ref.magnitude = r.magnitude;
  return ref;
}

// A run's time axis with its fault onset and first alarm marked.
void MarkRun(const RunSeries& s, bool line_up, vega::Plot* p) {
  const RunRecord& r = s.record;
  p->set_run(RefOf(s));
  if (line_up) p->set_min_left(72);  // the panels of one joint share their time axis: line them up
  p->x().label = "time (s)";
  p->x().min = 0;
  p->x().max = s.t_s.empty() ? 1 : s.t_s.back();
  if (!r.family.empty()) {
    p->VLine(r.onset_s, "fault onset " + Fixed(r.onset_s, 2) + " s (" + r.family + ")",
             vega::Stroke{"#d62728", 1.6, "6 3", 1});
  }
  if (s.first_alarm_s) {
    p->VLine(*s.first_alarm_s,
             "first alarm " + Fixed(*s.first_alarm_s, 2) + " s" +
                 (s.first_alarm_family.empty() ? "" : " (" + s.first_alarm_family + ")"),
             vega::Stroke{"#000", 1.6, "", 1});
  }
}

// The efficiencies of joint j per judged window of a run, measured (solid) against what a
// healthy joint would show (dashed); `all` false: the overall η only (small multiples).
vega::Plot EfficiencyPlot(const RunSeries& s, int j, const std::string& id, const std::string& title, int width,
                          int height, bool all) {
  vega::Plot eff(id, title, width, height);
  const bool judged = std::any_of(s.monitor.windows.begin(), s.monitor.windows.end(),
                                  [&](const EfficiencyWindow& w) { return w.joint == j && w.used; });
  if (all) {
    eff.set_caption(judged ? std::string("Judged windows; bar: the window's span; dashed: what a healthy joint would show "
                                         "for the same motion.") + (s.first_alarm_s ? "" : " No alarm in this run.")
                           : std::string("Empty: the monitor judged no window of this joint (it did not move or carry "
                                         "load enough)."));
  }
  eff.y().label = "efficiency (fraction)";
  struct Series {
    const char* name;
    const char* color;
    double EfficiencyWindow::*measured;
    double EfficiencyWindow::*expected;
  };
  const Series series[] = {{"η = E_out / E_supply", "#1f77b4", &EfficiencyWindow::eta, &EfficiencyWindow::eta_expected},
                           {"η_m (mechanical)", "#ff7f0e", &EfficiencyWindow::eta_m, &EfficiencyWindow::eta_m_expected},
                           {"η_e (electrical)", "#2ca02c", &EfficiencyWindow::eta_e, &EfficiencyWindow::eta_e_expected}};
  double ymin = 0, ymax = 1;
  for (const Series& se : series) {
    if (!all && se.measured != &EfficiencyWindow::eta) continue;
    std::vector<double> x0, x1, m, e;
    for (const EfficiencyWindow& w : s.monitor.windows) {
      if (w.joint != j || !w.used) continue;
      x0.push_back(w.t_start_s);
      x1.push_back(w.t_end_s);
      m.push_back(w.*se.measured);
      e.push_back(w.*se.expected);
      for (double v : {w.*se.measured, w.*se.expected}) {
        if (std::isfinite(v)) ymin = std::min(ymin, v), ymax = std::max(ymax, v);
      }
    }
    eff.Segments(std::string(se.name) + " measured", x0, x1, m, vega::Stroke{se.color, 2.4, "", 1},
                 vega::Marker::kCircle);
    eff.Segments(std::string(se.name) + " healthy", x0, x1, e, vega::Stroke{se.color, 1.6, "5 3", 1},
                 vega::Marker::kNone);
  }
  // Wild ratios (a window right at a fault's onset) are clipped rather than squashing the rest.
  // A small multiple keeps the data's own range: a missed fault's deviation is small.
  if (all) {
    eff.y().min = std::max(-0.5, ymin);
    eff.y().max = std::min(1.5, ymax);
  }
  MarkRun(s, all, &eff);
  return eff;
}

}  // namespace

std::string RunSection(const ReportData& d) {
  const RunSeries& s = d.run;
  std::string o = "<section id=\"run\"><h2>One run over time</h2>";
  if (!d.recorded_runs.empty()) {
    return o + "<p class=\"missing\">Empty because " + Escape(d.recorded_runs) + ".</p></section>";
  }
  if (!s.error.empty()) {
    return o + "<p class=\"missing\">Could not re-simulate " + Escape(s.run_id.empty() ? "a run" : s.run_id) + ": " +
           Escape(s.error) + "</p></section>";
  }
  const RunRecord& r = s.record;
  o += "<p>Run <code>" + Escape(s.run_id) + "</code> (" + Escape(s.why) + "; choose another with <code>--run "
       "RUN_ID</code>), re-simulated with a second monitor on the same signals. Every joint, the faulted one first.</p>";
  std::vector<std::vector<std::string>> rows = {
      {"fault", r.fault.is_null() ? "none (healthy run)" : "<code>" + Escape(r.fault.dump()) + "</code>"},
      {"re-simulated", Escape(RecordText(r))}};
  if (s.stored) {
    const bool same = s.stored->detected == r.detected && s.stored->detection_time_s == r.detection_time_s &&
                      s.stored->isolated_family == r.isolated_family && s.stored->isolated_joint == r.isolated_joint;
    rows.push_back({"results.jsonl", Escape(RecordText(*s.stored)) +
                                         (same ? " <span class=\"met\">(same)</span>"
                                               : " <span class=\"missed\">(differs: the build or the files changed)</span>")});
  }
  o += HtmlTable({"", ""}, rows, "kv");
  for (size_t k = 0; k < s.joints.size(); ++k) {
    const int j = s.joints[k];
    const std::string jt = "joint " + std::to_string(j);
    std::string heading = "Joint " + std::to_string(j);
    if (j == r.joint && !r.family.empty()) heading += " (faulted: " + r.family + ")";
    if (r.isolated_joint == j && !r.isolated_family.empty()) heading += " (named: " + r.isolated_family + ")";
    o += "<h3>" + Escape(heading) + "</h3>";
    vega::Plot eff = EfficiencyPlot(s, j, "run-j" + std::to_string(j) + "-efficiency",
                                    "Efficiencies of " + jt + " per window", kFullWidth, 320, true);

    std::vector<double> tx, ty;
    vega::Plot cur("run-j" + std::to_string(j) + "-current", "Currents of " + jt, kFullWidth, 280);
    cur.y().label = "current (A)";
    Thin(s.t_s, s.i_cmd_A[k], 1400, &tx, &ty);
    cur.Line("commanded current i (after the DAC)", tx, ty, vega::Stroke{"#1f77b4", 1.3, "", 1});
    tx.clear(), ty.clear();
    Thin(s.t_s, s.i_supply_A[k], 1400, &tx, &ty);
    cur.Line("supply current I_d (measured, period mean)", tx, ty, vega::Stroke{"#d62728", 1.1, "", 0.85});
    MarkRun(s, true, &cur);

    vega::Plot tor("run-j" + std::to_string(j) + "-torque", "Torque sensor of " + jt, kFullWidth, 260);
    tor.y().label = "torque (N m)";
    tx.clear(), ty.clear();
    Thin(s.t_s, s.tau_sensor_Nm[k], 1400, &tx, &ty);
    tor.Line("torque-sensor reading τ_s", tx, ty, vega::Stroke{"#2ca02c", 1.3, "", 1});
    MarkRun(s, true, &tor);
    o += "<div class=\"plots\">" + eff.Render() + cur.Render() + tor.Render() + "</div>";
  }
  return o + "</section>";
}

std::string WrongRunsSection(const ReportData& d) {
  std::string o = "<section id=\"wrong-runs\"><h2>Missed and misnamed runs, one small plot each</h2>";
  if (!d.recorded_runs.empty()) {
    return o + "<p class=\"missing\">Empty because " + Escape(d.recorded_runs) + " (the runs scored wrong: the table "
               "above and <code>results.csv</code>'s <code>miss_reason</code>).</p></section>";
  }
  if (d.wrong_runs.empty()) {
    return o + "<p>None: every faulty run was detected and named with its family and joint" +
           (d.wrong_count > 0 ? std::string(" (the runs scored wrong are healthy runs that alarmed)") : std::string()) +
           ".</p></section>";
  }
  o += "<p>The overall efficiency η of each run's faulted joint per judged window (solid) against a healthy joint "
       "(dashed), with the fault's onset and the first alarm, the first " + std::to_string(d.wrong_runs.size()) +
       " missed or misnamed faulty runs in case order (at most " + std::to_string(ReportData::kSmallMultiples) +
       "; all of them: the table above and <code>results.csv</code>'s <code>miss_reason</code>). Click a plot to copy "
       "its run's <code>armfault trace</code> command.</p><div class=\"plots\">";
  for (size_t k = 0; k < d.wrong_runs.size(); ++k) {
    const RunSeries& s = d.wrong_runs[k];
    const RunRecord& r = s.record;
    if (!s.error.empty()) {
      o += "<p class=\"missing\">" + Escape(s.run_id) + ": could not re-simulate: " + Escape(s.error) + "</p>";
      continue;
    }
    const int j = r.joint > 0 ? r.joint : s.joints.empty() ? 1 : s.joints.front();
    vega::Plot p = EfficiencyPlot(s, j, "wrong-" + std::to_string(k), s.run_id, 410, 250, false);
    p.set_caption(s.why + (r.detected && !r.isolated_family.empty()
                               ? " (named " + r.isolated_family + " on joint " + std::to_string(r.isolated_joint) + ")"
                               : ""));
    o += p.Render();
  }
  return o + "</div></section>";
}

}  // namespace armfault::report
