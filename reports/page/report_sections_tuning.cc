// The sections drawn from tuning.json: operating point, ROC curves, latency against threshold.
#include "reports/page/report_sections.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "core/base/json_input.h"
#include "reports/page/report_common.h"
#include "reports/page/vega_plot.h"

namespace armfault::report {


namespace {

// A section that needs tuning results and has none: why, and what to run.
std::string TuneFirst(const ReportData& d) {
  return "<p class=\"missing\">No tuning results: " + CodeSpans(d.tuning_source) + ".</p>";
}

}  // namespace

std::vector<std::string> RateCalibrationHead() {
  return {"set for [/h]", "healthy hours", "false alarms", "measured [/h] (exact 95 %)", "the target's 95 % count",
          "the count seen", "detection", "median latency"};
}

std::vector<std::vector<std::string>> RateCalibrationRows(const json& tuning) {
  auto g3 = [](double x) {  // three significant digits
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", x);
    return std::string(buf);
  };
  std::vector<std::vector<std::string>> rows;
  const json* cal = Field(tuning, "rate_calibration");
  const json* points = cal != nullptr ? Field(*cal, "points") : nullptr;
  if (points == nullptr || !points->is_array()) return rows;
  for (const json& p : *points) {
    const json* in = Field(p, "measured_interval_per_hour");
    const json* counts = Field(p, "target_count_interval");
    const json* consistent = Field(p, "consistent");
    const std::optional<double> measured = Num(p, "measured_per_hour");
    const std::optional<double> rate = Num(p, "detection_rate");
    const bool has_in = measured && in && in->is_array() && in->size() == 2 && (*in)[0].is_number() && (*in)[1].is_number();
    const bool has_counts = counts && counts->is_array() && counts->size() == 2;
    rows.push_back({FormatNumber(Num(p, "target_per_hour").value_or(0)), g3(Num(p, "healthy_hours").value_or(0)),
                    std::to_string(Count(p, "false_alarms")),
                    has_in ? g3(*measured) + " (" + g3((*in)[0].get<double>()) + " to " + g3((*in)[1].get<double>()) + ")"
                           : "–",
                    has_counts ? counts->at(0).dump() + " to " + counts->at(1).dump() : "–",
                    consistent && consistent->is_boolean() ? (consistent->get<bool>() ? "inside" : "outside") : "–",
                    rate ? Pct(*rate) : "–", SecondsText(Num(p, "median_latency_s"))});
  }
  return rows;
}

std::string OperatingPointSection(const ReportData& d) {
  std::string o = "<section id=\"operating-point\"><h2>Operating point</h2>";
  if (!d.tuning) return o + TuneFirst(d) + "</section>";
  const json& t = *d.tuning;
  const json empty = json::object();
  const json& op = Field(t, "operating_point") ? t["operating_point"] : empty;
  const json& def = Field(t, "default_point") ? t["default_point"] : empty;
  const json& sel = Field(t, "selection") ? t["selection"] : empty;
  const bool halves = Field(sel, "held_out") != nullptr;
  o += "<p>Chosen by the rule <b>" + Escape(RuleText(Field(t, "rule"))) + "</b> among " +
       std::to_string(Count(t, "settings")) + " threshold settings scored on this campaign's runs" +
       (Str(sel, "split").empty() ? "" : " (" + Escape(Str(sel, "split")) + ")") + ". Tuning: " +
       CodeSpans(d.tuning_source) + "." + Escape(TuningLeftOutText(t)) + "</p>";
  // Thresholds: operating beside the monitor's defaults.
  std::vector<std::vector<std::string>> rows;
  std::map<std::string, double> defaults;
  if (const json* params = Field(t, "parameters"); params != nullptr && params->is_array()) {
    for (const json& p : *params) {
      if (Num(p, "default")) defaults[Str(p, "name")] = *Num(p, "default");
    }
  }
  if (const json* setting = Field(op, "setting"); setting != nullptr && setting->is_object()) {
    for (const auto& [key, value] : setting->items()) {
      auto it = defaults.find(key);
      rows.push_back({Escape(key), Escape(value.is_number() ? FormatNumber(value.get<double>()) : value.dump()),
                      it == defaults.end() ? "–" : Escape(FormatNumber(it->second))});
    }
  }
  o += "<div class=\"tables\">";
  if (!rows.empty()) o += "<div><h3>Thresholds</h3>" + HtmlTable({"threshold", "operating point", "as run"}, rows) + "</div>";
  auto lat = [](const json& p, const char* key) { return Escape(SecondsText(Num(p, key))); };
  // The operating point over every run, on the half it was chosen on and on the held-out
  // half (its honest rates), beside the thresholds as run.
  std::vector<const json*> cols = {&op};
  std::vector<std::string> head = {"metric", "operating point (all runs)"};
  if (halves) {
    cols.push_back(Field(sel, "chosen_on"));
    cols.push_back(Field(sel, "held_out"));
    head.push_back("on the half it was chosen on");
    head.push_back("on the held-out half");
  }
  cols.push_back(&def);
  head.push_back("thresholds as run");
  std::vector<std::vector<std::string>> rates;
  for (const auto& [label, key] : std::vector<std::pair<std::string, std::string>>{
           {"detection rate", "detection_rate"},
           {"false-alarm rate", "false_alarm_rate"},
           {"alarm-before-onset rate", "alarm_before_onset_rate"},
           {"isolation accuracy", "isolation_accuracy"},
           {"latency median", "latency_median_s"},
           {"latency p95", "latency_p95_s"}}) {
    std::vector<std::string> row = {label};
    for (const json* c : cols) {
      const json& p = c != nullptr ? *c : empty;
      row.push_back(key.size() > 2 && key.compare(key.size() - 2, 2, "_s") == 0 ? lat(p, key.c_str())
                                                                                 : Escape(RateText(TuningRate(Field(p, key)))));
    }
    rates.push_back(row);
  }
  o += "<div><h3>Rates</h3>" + HtmlTable(head, rates) + "</div></div>";
  o += "<div class=\"tables\">";
  if (const json* pf = Field(op, "per_family"); pf != nullptr && pf->is_object() && !pf->empty()) {
    std::vector<std::vector<std::string>> frows;
    for (const auto& [family, m] : pf->items()) {
      frows.push_back({Escape(family), Escape(RateText(TuningRate(Field(m, "detection_rate")))),
                       Escape(RateText(TuningRate(Field(m, "isolation_accuracy")))), lat(m, "latency_median_s"),
                       lat(m, "latency_p95_s")});
    }
    o += "<div><h3>Per family at the operating point</h3>" +
         HtmlTable({"family", "detection", "isolation", "latency median", "latency p95"}, frows) + "</div>";
  }
  // A sequential monitor: each target rate beside the one its healthy runs measured.
  if (Field(t, "rate_calibration") != nullptr) {
    std::vector<std::vector<std::string>> crows = RateCalibrationRows(t);
    for (auto& row : crows) {
      for (std::string& cell : row) cell = Escape(cell);
    }
    o += "<div><h3>Set for and measured: false alarms per healthy hour</h3>" + HtmlTable(RateCalibrationHead(), crows) +
         "<p>The sequential decision's thresholds follow its target rate (docs/monitor.md, \"Sequential "
         "decision\"); each healthy run counts until its first alarm.</p></div>";
  }
  return o + "</div></section>";
}

namespace {

// One ROC curve of tuning.json as the report reads it.
struct RocView {
  std::string name;
  bool overall = false;
  std::string parameter;  // the family's own swept threshold; "" for none
  std::vector<double> fa, det;
  std::vector<std::string> tips;
  bool swept = false;
  std::string why_not;  // when not swept
  std::optional<double> auc;
  double auc_from = 0, auc_to = 0;
};

std::string PctRange(double lo, double hi) { return lo == hi ? Pct(lo) : Pct(lo) + " to " + Pct(hi); }

// A curve is swept when it has a threshold of its own (the overall frontier: the whole grid)
// and at least two distinct points. Its AUC is shown only as tuning.json measured it: over
// the false-alarm range its points span, nothing extrapolated to (0, 0) or (1, 1).
RocView ReadRocCurve(const std::string& name, const json& curve) {
  RocView v;
  v.name = name;
  v.overall = name == "overall";
  v.parameter = Str(curve, "parameter");
  std::set<std::pair<double, double>> distinct;
  if (const json* pts = Field(curve, "points"); pts != nullptr && pts->is_array()) {
    for (const json& p : *pts) {
      const auto fa = Num(p, "false_alarm_rate"), det = Num(p, "detection_rate");
      if (!fa || !det) continue;
      v.fa.push_back(*fa);
      v.det.push_back(*det);
      distinct.insert({*fa, *det});
      std::string tip = name + ": false alarms " + Pct(*fa) + ", detection " + Pct(*det);
      if (Num(p, "threshold")) tip += ", " + v.parameter + " = " + FormatNumber(*Num(p, "threshold"));
      if (const std::string s = SettingText(Field(p, "setting")); !s.empty()) tip += "; " + s;
      v.tips.push_back(tip);
    }
  }
  const bool own = v.overall || !v.parameter.empty();
  const json* flag = Field(curve, "swept");
  const bool marked_unswept = flag != nullptr && flag->is_boolean() && !flag->get<bool>();
  v.swept = own && distinct.size() >= 2 && !marked_unswept;
  if (!own) {
    v.why_not = "no threshold of its own is swept (its detectors are not on the grid)";
    if (!v.det.empty()) {
      v.why_not += "; along the overall frontier it is detected in " +
                   PctRange(*std::min_element(v.det.begin(), v.det.end()), *std::max_element(v.det.begin(), v.det.end())) +
                   " of its runs";
    }
  } else if (distinct.empty()) {
    v.why_not = "no points";
  } else if (distinct.size() == 1) {
    v.why_not = "one operating point only (false alarms " + Pct(distinct.begin()->first) + ", detection " +
                Pct(distinct.begin()->second) + "): " +
                (v.overall ? std::string("every setting of the grid gave these rates")
                           : "every " + v.parameter + " value swept gave these rates");
  } else if (marked_unswept) {
    v.why_not = "tuning.json marks it as not swept";
  }
  if (v.swept) {
    const json* range = Field(curve, "auc_false_alarm_range");
    const auto auc = Num(curve, "auc");
    if (auc && range != nullptr && range->is_array() && range->size() == 2 && (*range)[0].is_number() &&
        (*range)[1].is_number() && (*range)[1].get<double>() > (*range)[0].get<double>()) {
      v.auc = *auc;
      v.auc_from = (*range)[0].get<double>();
      v.auc_to = (*range)[1].get<double>();
    }
  }
  return v;
}


// A marked point of the ROC plots, from tuning.json.
struct RocMark {
  std::string label, color;
  vega::Marker marker;
  double size;
  const json* point;
};
using PlacedRocMark = std::pair<RocMark, std::pair<double, double>>;  // at (false alarms, detection)

// The marked points: the thresholds as run, the operating point over every run and, when
// it was chosen on one half, on each half; those with both rates.
std::vector<PlacedRocMark> PlacedRocMarks(const json& tuning) {
  std::vector<RocMark> marks = {{"thresholds as run", "#888888", vega::Marker::kTriangle, 5, Field(tuning, "default_point")},
                                {"operating point (all runs)", "#000000", vega::Marker::kDiamond, 6,
                                 Field(tuning, "operating_point")}};
  const json* selection = Field(tuning, "selection");
  if (selection != nullptr) {
    marks.push_back({"operating point on the runs it was chosen on", "#1a7f37", vega::Marker::kDiamond, 4,
                     Field(*selection, "chosen_on")});
    marks.push_back({"operating point on the held-out runs", "#b00020", vega::Marker::kDiamond, 4,
                     Field(*selection, "held_out")});
  }
  std::vector<PlacedRocMark> placed;
  for (const RocMark& m : marks) {
    if (m.point == nullptr) continue;
    const Rate fa = TuningRate(Field(*m.point, "false_alarm_rate")), det = TuningRate(Field(*m.point, "detection_rate"));
    if (fa.value && det.value) placed.push_back({m, {*fa.value, *det.value}});
  }
  return placed;
}

// One ROC plot of the swept curves (the overall frontier on top) and the marked points, the
// false-alarm axis from 0 to x_max.
std::string RocPlot(const std::string& id, const std::string& title, double x_max, const std::string& caption,
                    const std::vector<RocView>& swept, const std::vector<PlacedRocMark>& placed) {
  vega::Plot plot(id, title, kFullWidth, 430);
  plot.set_caption(caption);
  plot.x().label = "false-alarm rate (fraction of healthy runs alarmed; axis 0 to " + FormatNumber(x_max) + ")";
  plot.x().min = 0;
  plot.x().max = x_max;
  plot.y().label = "detection rate (fraction of faulty runs; a family: of its runs)";
  plot.y().min = 0;
  plot.y().max = 1;
  for (size_t k = swept.size(); k-- > 0;) {  // the overall frontier last: on top
    const RocView& v = swept[k];
    const std::string color = FamilyColor(v.overall ? "overall" : v.name);
    std::string label = v.overall ? "overall frontier" : v.name + " (" + v.parameter + " swept)";
    label += v.auc ? ", AUC " + Fixed(*v.auc, 3) + " over false alarms " + FormatNumber(v.auc_from) + " to " +
                         FormatNumber(v.auc_to)
                   : ", no AUC: every point at one false-alarm rate";
    std::vector<size_t> order(v.fa.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return std::tie(v.fa[a], v.det[a]) < std::tie(v.fa[b], v.det[b]); });
    std::vector<double> xs, ys;
    for (size_t i : order) xs.push_back(v.fa[i]), ys.push_back(v.det[i]);
    plot.Line("", xs, ys, vega::Stroke{color, v.overall ? 2.6 : 1.6, "", 0.9});
    plot.Points(label, v.fa, v.det, {}, {}, color, v.overall ? vega::Marker::kCircle : vega::Marker::kSquare, v.tips,
                v.overall ? 3.2 : 2.8);
  }
  for (const auto& [m, p] : placed) {
    plot.Points(m.label, {p.first}, {p.second}, {}, {}, m.color, m.marker,
                {m.label + ": false alarms " + Pct(p.first) + ", detection " + Pct(p.second) + "; " +
                 SettingText(Field(*m.point, "setting"))},
                m.size);
  }
  return plot.Render();
}
}  // namespace

std::string RocSection(const ReportData& d) {
  std::string o = "<section id=\"roc\"><h2>ROC curves</h2>";
  if (!d.tuning) return o + TuneFirst(d) + "</section>";
  const json* roc = Field(*d.tuning, "roc");
  if (roc == nullptr || !roc->is_object() || roc->empty()) {
    return o + "<p class=\"missing\">No ROC curves: tuning.json has no \"roc\" (it is not from `armfault tune`); run " +
           CodeSpans("`armfault tune " + d.dir + "`") + ".</p></section>";
  }
  std::vector<RocView> swept, unswept;
  if (const json* overall = Field(*roc, "overall")) {
    RocView v = ReadRocCurve("overall", *overall);
    (v.swept ? swept : unswept).push_back(v);
  }
  for (const auto& [name, curve] : roc->items()) {
    if (name == "overall") continue;
    RocView v = ReadRocCurve(name, curve);
    (v.swept ? swept : unswept).push_back(v);
  }

  const std::vector<PlacedRocMark> placed = PlacedRocMarks(*d.tuning);
  const json* selection = Field(*d.tuning, "selection");

  std::string notes;
  const std::string split = selection != nullptr ? Str(*selection, "split") : "";
  notes += "<li>Operating point: chosen by the rule <b>" + Escape(RuleText(Field(*d.tuning, "rule"))) + "</b>" +
           (split.empty() ? "" : " (" + Escape(split) + ")") + "; the black diamond gives its rates over every run" +
           (placed.size() > 2 ? ", the green and red ones on the half it was chosen on and on the held-out half." : ".") +
           "</li>";
  for (const RocView& v : unswept) {
    notes += "<li>Not drawn: <b>" + Escape(v.name == "overall" ? "overall frontier" : v.name) + "</b>: " +
             Escape(v.why_not) + "; no AUC.</li>";
  }
  notes += "<li>AUC: the area under the measured points only, between the smallest and the largest false-alarm rate "
           "they reach (a partial AUC, not comparable with one over 0 to 1); nothing is extrapolated to (0, 0) or "
           "(1, 1), and a curve that was not swept has none.</li>";
  if (swept.empty()) {
    return o + "<p class=\"missing\">No ROC curve to draw: no threshold sweep changed the rates (every curve has at "
               "most one distinct point, or no threshold of its own). Widen the sweep (" +
           CodeSpans("`armfault tune " + d.dir + " --sweep ...`") + ", docs/tuning.md) or run more healthy runs.</p><ul class=\"note\">" +
           notes + "</ul></section>";
  }

  // The false-alarm axis shows the range that matters: up to a little above the largest rate
  // measured (at least 0 to 0.05), not 0 to 1.
  auto axis_end = [](double largest) {
    for (double c : {0.05, 0.1, 0.2, 0.3, 0.5, 0.75}) {
      if (c >= 1.05 * largest && c > largest) return c;
    }
    return 1.0;
  };
  double fa_max = 0, marked_max = 0;
  for (const RocView& v : swept) {
    for (double x : v.fa) fa_max = std::max(fa_max, x);
  }
  for (const auto& [m, p] : placed) marked_max = std::max(marked_max, p.first);
  fa_max = std::max(fa_max, marked_max);
  const json* rule = Field(*d.tuning, "rule");
  const double ceiling = rule != nullptr ? Num(*rule, "false_alarm_ceiling").value_or(0) : 0;
  const double x_max = axis_end(fa_max);
  std::string plots = RocPlot("roc", "Detection against false alarms, per threshold setting", x_max,
                              std::string(x_max < 1 ? "False-alarm axis zoomed to 0 to " : "False-alarm axis 0 to ") +
                                  FormatNumber(x_max) + " (largest measured: " + FormatNumber(fa_max) +
                                  "). Each point is one threshold setting; lines join measured points only.",
                              swept, placed);
  // When the curves reach far, a second plot zooms on the low end where the operating point
  // lies (up to a little above it and the rule's ceiling); the points beyond are cut off.
  const double low_max = axis_end(std::max(marked_max, ceiling));
  if (low_max <= x_max / 4) {
    long beyond = 0, within = 0;
    for (const RocView& v : swept) {
      for (double x : v.fa) (x > low_max ? beyond : within) += 1;
    }
    if (within > 0 && beyond > 0) {
      plots += RocPlot("roc-low-false-alarms", "The low false-alarm end, where the operating point lies", low_max,
                       "Zoomed to false alarms 0 to " + FormatNumber(low_max) + ": " + std::to_string(beyond) +
                           " points lie beyond the axis (see the plot above).",
                       swept, placed);
    }
  }
  return o + "<div class=\"plots\">" + plots + "</div><ul class=\"note\">" + notes + "</ul></section>";
}

std::string LatencyThresholdSection(const ReportData& d) {
  std::string o = "<section id=\"latency-threshold\"><h2>Latency against threshold</h2>";
  if (!d.tuning) return o + TuneFirst(d) + "</section>";
  const json* lat = Field(*d.tuning, "latency");
  if (lat == nullptr || !lat->is_object() || lat->empty()) {
    return o + "<p class=\"missing\">No latency curves: no family of this campaign has a swept threshold of its own "
               "(kt_factor, resistance_factor, friction_factor or sensor_drift_Nm).</p></section>";
  }
  std::map<std::string, double> defaults;
  if (const json* params = Field(*d.tuning, "parameters"); params != nullptr && params->is_array()) {
    for (const json& p : *params) {
      if (Num(p, "default")) defaults[Str(p, "name")] = *Num(p, "default");
    }
  }
  const json* op = Field(*d.tuning, "operating_point");
  const json* setting = op != nullptr ? Field(*op, "setting") : nullptr;
  o += "<p>Time from the fault's onset to the first alarm over the detected runs of each family, as that family's "
       "threshold moves (the other thresholds at the operating point).</p><div class=\"plots\">";
  std::string notes;
  for (const auto& [family, f] : lat->items()) {
    const std::string param = Str(f, "parameter");
    std::vector<double> xs, med, p95;
    std::vector<std::string> tips;
    if (const json* pts = Field(f, "points"); pts != nullptr && pts->is_array()) {
      for (const json& p : *pts) {
        const auto x = Num(p, "threshold");
        if (!x) continue;
        xs.push_back(*x);
        med.push_back(Num(p, "median_s").value_or(std::nan("")));
        p95.push_back(Num(p, "p95_s").value_or(std::nan("")));
        tips.push_back(param + " = " + FormatNumber(*x) + ": median " + SecondsText(Num(p, "median_s")) + ", p95 " +
                       SecondsText(Num(p, "p95_s")) + " over " + std::to_string(Count(p, "detected")) + " detected runs");
      }
    }
    const bool any_latency = std::any_of(med.begin(), med.end(), [](double v) { return std::isfinite(v); });
    if (xs.size() < 2 || !any_latency) {
      notes += "<li>" + Escape(family) + ": " +
               Escape(xs.size() < 2 ? "one threshold value only (" + param + " not swept): no curve"
                                    : "no run detected at any swept " + param + ": no latency") +
               ".</li>";
      continue;
    }
    vega::Plot plot("latency-threshold-" + IdPart(family), family, kHalfWidth, 320);
    plot.x().label = (param.empty() ? std::string("threshold") : WithUnit(param)) + ", threshold";
    plot.y().label = "latency after onset (s)";
    plot.y().include_zero = true;
    const std::string color = FamilyColor(family);
    plot.Line("95th percentile", xs, p95, vega::Stroke{color, 1.6, "5 3", 1}, vega::Marker::kTriangle);
    plot.Line("median", xs, med, vega::Stroke{color, 2.2, "", 1});
    plot.Points("", xs, med, {}, {}, color, vega::Marker::kCircle, tips, 3.5);
    if (setting != nullptr && Num(*setting, param)) {
      plot.VLine(*Num(*setting, param), "operating " + FormatNumber(*Num(*setting, param)),
                 vega::Stroke{"#000", 1.4, "", 1});
    }
    if (auto it = defaults.find(param); it != defaults.end()) {
      plot.VLine(it->second, "as run " + FormatNumber(it->second), vega::Stroke{"#888", 1.4, "4 3", 1});
    }
    o += plot.Render();
  }
  o += "</div>";
  if (!notes.empty()) o += "<ul class=\"note\">" + notes + "</ul>";
  return o + "</section>";
}

}  // namespace armfault::report
