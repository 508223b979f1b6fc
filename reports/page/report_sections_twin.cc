// The twin against a recording (`armfault report DIR --twin unit.json`): one recorded run's
// signals beside the twin's simulation of the same motion, and their residuals.
#include <cmath>

#include "reports/page/report_common.h"
#include "reports/page/report_sections.h"
#include "reports/page/vega_plot.h"

namespace armfault::report {

namespace {

// The signals drawn over time (the supply current is in the table: the power shows it).
bool Plotted(const TwinSignal& s) { return s.key != "supply_current_A"; }

std::string Ratio(double residual, double recorded) {
  return recorded > 0 && std::isfinite(residual) ? Fixed(100.0 * residual / recorded, 1) + " %" : "–";
}

}  // namespace

std::vector<std::vector<std::string>> TwinResidualRows(const TwinComparison& c) {
  std::vector<std::vector<std::string>> rows;
  for (const JointComparison& j : c.joints) {
    for (const TwinSignal& s : j.signals) {
      rows.push_back({std::to_string(j.joint), s.label + " (" + s.unit + ")", Sig4(s.recorded_rms), Sig4(s.twin_rms),
                      Sig4(s.residual_rms), Sig4(s.residual_mean), Ratio(s.residual_rms, s.recorded_rms)});
    }
  }
  return rows;
}

const std::vector<std::string>& TwinResidualHead() {
  static const std::vector<std::string> head = {"joint",        "signal",        "recorded RMS", "twin RMS",
                                                "residual RMS", "residual mean", "residual RMS / recorded RMS"};
  return head;
}

std::string TwinRunText(const TwinComparison& c) {
  const double span_s = c.t_s.empty() ? 0 : c.t_s.back() - c.t_s.front();
  return "Run `" + c.run_id + "` (" + c.why + ") as recorded in `" + c.signals_file + "`, beside the twin `" + c.twin_file +
         "` (robot \"" + c.twin_name + "\") simulated along the run's own recorded reference (q_ref of every joint) for its " +
         std::to_string(c.t_s.size()) + " ticks (" + Fixed(span_s, 2) + " s; the twin's sensor noise from seed " +
         std::to_string(c.seed) + "). Residual: recorded − twin, tick by tick; RMS over the ticks where both are numbers." +
         (c.family.empty() ? "" : " The run is labelled faulty (" + c.family + "): the residual shows the fault.");
}

std::string TwinSection(const ReportData& d) {
  const TwinComparison& c = *d.twin;
  std::string o = "<section id=\"twin\"><h2>Twin against the recording</h2>";
  o += "<p>" + CodeSpans(TwinRunText(c)) + " Choose another run with <code>--twin-run RUN_ID</code>. A twin of the "
       "very unit leaves the sensors' noise and quantisation in the residual; a wrong value (K_T, friction, payload) "
       "leaves a systematic part that follows the motion (docs/calibration.md, \"Compare\").</p>";
  std::vector<std::vector<std::string>> rows = TwinResidualRows(c);
  for (auto& row : rows) {
    for (auto& cell : row) cell = Escape(cell);
  }
  o += HtmlTable(TwinResidualHead(), rows);
  const double end_s = c.t_s.empty() ? 1 : c.t_s.back();
  for (const JointComparison& j : c.joints) {
    o += "<h3>Joint " + std::to_string(j.joint) + "</h3><div class=\"plots\">";
    for (const TwinSignal& s : j.signals) {
      if (!Plotted(s)) continue;
      const std::string id = "twin-j" + std::to_string(j.joint) + "-" + IdPart(s.key);
      const std::string axis = s.label + " (" + s.unit + ")";
      auto mark = [&](vega::Plot* p) {
        p->x().label = "time (s)";
        p->x().min = c.t_s.empty() ? 0 : c.t_s.front();
        p->x().max = end_s;
        p->set_min_left(72);
        if (c.onset_s) p->VLine(*c.onset_s, "fault onset " + Fixed(*c.onset_s, 2) + " s (" + c.family + ")",
                                vega::Stroke{"#d62728", 1.6, "6 3", 1});
      };
      vega::Plot both(id, "Joint " + std::to_string(j.joint) + ": " + s.label, kHalfWidth, 260);
      both.y().label = axis;
      std::vector<double> tx, ty;
      Thin(c.t_s, s.recorded, 900, &tx, &ty);
      both.Line("recorded", tx, ty, vega::Stroke{"#1f77b4", 1.3, "", 1});
      tx.clear(), ty.clear();
      Thin(c.t_s, s.twin, 900, &tx, &ty);
      both.Line("twin", tx, ty, vega::Stroke{"#ff7f0e", 1.3, "5 2", 0.9});
      mark(&both);

      std::vector<double> residual(s.recorded.size());
      for (size_t k = 0; k < residual.size(); ++k) residual[k] = s.recorded[k] - s.twin[k];
      vega::Plot res(id + "-residual", "Joint " + std::to_string(j.joint) + ": residual of the " + s.label, kHalfWidth, 260);
      res.set_caption("recorded − twin; RMS " + Sig4(s.residual_rms) + " " + s.unit + " (" +
                      Ratio(s.residual_rms, s.recorded_rms) + " of the recorded RMS), mean " + Sig4(s.residual_mean) +
                      " " + s.unit + ".");
      res.y().label = "residual (" + s.unit + ")";
      tx.clear(), ty.clear();
      Thin(c.t_s, residual, 900, &tx, &ty);
      res.Line("recorded − twin", tx, ty, vega::Stroke{"#2ca02c", 1.2, "", 1});
      res.HLine(0, "", vega::Stroke{"#888", 1, "3 3", 1});
      mark(&res);
      o += both.Render() + res.Render();
    }
    o += "</div>";
  }
  return o + "</section>";
}

}  // namespace armfault::report
