// The sections of detection against fault magnitude: detection probability (as run and at the
// operating point) and the detection boundary of boundary.json.
#include "reports/page/report_sections.h"

#include <map>

#include "campaigns/scoring/campaign_summary.h"
#include "campaigns/tuning/tuning.h"
#include "core/base/json_input.h"
#include "faults/fault.h"
#include "reports/page/report_common.h"
#include "reports/page/vega_plot.h"

namespace armfault::report {


namespace {

// Whether tuning.json's operating point uses other thresholds than the campaign ran with.
bool OperatingPointDiffers(const json& tuning) {
  const json* op = Field(tuning, "operating_point");
  const json* def = Field(tuning, "default_point");
  const json* a = op != nullptr ? Field(*op, "setting") : nullptr;
  const json* b = def != nullptr ? Field(*def, "setting") : nullptr;
  return a == nullptr || b == nullptr || *a != *b;
}

// The fit of a family's detection as run: with runs at 2 or more numeric magnitudes, else null.
json AsRunFit(const PodAsRun& p) {
  if (p.magnitude_key.empty() || p.by_magnitude.size() < 2) return nullptr;
  return PodFitJson(p.magnitude_key, p.severities, p.hits);
}

// a90 or a90_95 of a fit as a table cell.
std::string A90Cell(const json* fit, const char* key, bool numeric) {
  if (!numeric) return "named variants";
  if (fit == nullptr) return "no fit";
  const json* v = Field(*fit, key);
  return v != nullptr && Num(*v, "magnitude") ? Sig4(*Num(*v, "magnitude")) : "not reached";
}

// One family's plot: every run as run (dots at 1 and 0), the detected fraction per magnitude
// with its Wilson interval, the fit as run and, when the operating point's thresholds differ
// (`tuned_differs`), its fit from `tuned` (tuning.json's detection_probability, or nullptr).
// *fit_possible: whether the runs allow a fit (2 or more numeric magnitudes).
std::string PodFamilyPlot(const std::string& family, const PodAsRun& p, const json* tuned, bool tuned_differs,
                          bool* fit_possible) {
  const std::string color = FamilyColor(family);
  const bool numeric = !p.magnitude_key.empty() && !p.by_magnitude.empty();
  const std::string key = numeric ? p.magnitude_key : p.name_key;
  vega::Plot plot("pod-" + IdPart(family), family, kHalfWidth, 340);
  plot.y().label = "detection probability (fraction of runs)";
  plot.y().min = 0;
  plot.y().max = 1;
  plot.x().label = numeric ? WithUnit(key) + ", fault magnitude"
                           : (key.empty() ? std::string("fault (no magnitude)") : key + " (named fault variant)");
  std::vector<double> xs, ys, lo, hi, hx, hy, mx, my;
  std::vector<std::string> tips, htips, mtips, categories;
  std::vector<vega::RunRef> hruns, mruns;
  long runs = 0, detected = 0;
  bool capped = false;
  auto add_cell = [&](double x, const std::string& mtext, const PodAsRun::Cell& c) {
    const RateInterval w = Wilson(c.detected, c.runs);
    runs += c.runs;
    detected += c.detected;
    xs.push_back(x);
    ys.push_back(w.rate);
    lo.push_back(w.low);
    hi.push_back(w.high);
    tips.push_back(key + " " + mtext + ": " + std::to_string(c.detected) + " of " + std::to_string(c.runs) +
                   " runs detected (" + Pct(w.rate) + ", 95 % Wilson [" + Fixed(100 * w.low, 1) + ", " +
                   Fixed(100 * w.high, 1) + "] %)");
    // The runs themselves, stacked a little inwards from 0 and 1 so that several show.
    for (size_t i = 0; i < c.hit_ids.size(); ++i) {
      hx.push_back(x);
      hy.push_back(1 - 0.014 * static_cast<double>(i % 5));
      htips.push_back("detected");
      hruns.push_back({c.hit_ids[i], family, i < c.hit_joints.size() ? c.hit_joints[i] : 0,
                       numeric ? std::optional<double>(x) : std::nullopt, numeric ? key : ""});
    }
    for (size_t i = 0; i < c.miss_ids.size(); ++i) {
      mx.push_back(x);
      my.push_back(0.014 * static_cast<double>(i % 5));
      mtips.push_back("missed");
      mruns.push_back({c.miss_ids[i], family, i < c.miss_joints.size() ? c.miss_joints[i] : 0,
                       numeric ? std::optional<double>(x) : std::nullopt, numeric ? key : ""});
    }
    capped = capped || c.hit_ids.size() < static_cast<size_t>(c.detected) ||
             c.miss_ids.size() < static_cast<size_t>(c.runs - c.detected);
  };
  if (numeric) {
    for (const auto& [m, c] : p.by_magnitude) add_cell(m, FormatNumber(m), c);
    // Severity grows to the right: a falling parameter (kt_factor, resistance_ohm) gets a reversed axis.
    plot.x().reversed = FaultSeverity(key, 2.0) < FaultSeverity(key, 1.0);
  } else {
    for (const auto& [name, c] : p.by_name) {
      add_cell(static_cast<double>(categories.size()), name.empty() ? "–" : name, c);
      categories.push_back(name.empty() ? "–" : name);
    }
    plot.x().categories = categories;
  }
  std::string caption = std::to_string(runs) + " runs at " + std::to_string(xs.size()) +
                        (numeric ? " magnitude" : " variant") + (xs.size() == 1 ? "" : "s") + ": " + std::to_string(detected) + " detected, " +
                        std::to_string(runs - detected) + " missed" + (capped ? " (dots: the first 40 of each)" : "") +
                        ". ";
  const json fit = AsRunFit(p);
  *fit_possible = !fit.is_null();
  const json* usable = fit.is_object() && fit.value("ok", false) ? &fit : nullptr;
  if (usable != nullptr) {
    std::vector<double> cx, cp, cl, ch;
    for (const json& c : (*usable)["curve"]) {
      cx.push_back(c["magnitude"].get<double>());
      cp.push_back(c["pod"].get<double>());
      cl.push_back(c["low"].get<double>());
      ch.push_back(c["high"].get<double>());
    }
    plot.Band("95 % confidence band (as run)", cx, cl, ch, color, 0.18);
    plot.Line("fitted as run", cx, cp, vega::Stroke{color, 2, "", 1});
    plot.HLine(0.9, "90 %", vega::Stroke{"#666", 1, "4 3", 1});
    if (const json* a = Field(*usable, "a90"); a != nullptr && Num(*a, "magnitude")) {
      plot.VLine(*Num(*a, "magnitude"), "a90 = " + Sig4(*Num(*a, "magnitude")), vega::Stroke{"#333", 1.4, "", 1});
    }
    if (const json* a = Field(*usable, "a90_95"); a != nullptr && Num(*a, "magnitude")) {
      plot.VLine(*Num(*a, "magnitude"), "a90/95 = " + Sig4(*Num(*a, "magnitude")),
                 vega::Stroke{"#b00020", 1.4, "5 3", 1});
    }
    if (Field(*usable, "a90_95") == nullptr) caption += "a90/95 not reached in the tested range.";
  } else if (!numeric) {
    caption += "Named variants: no fitted curve.";
  } else if (p.by_magnitude.size() < 2) {
    caption += "One magnitude only: no curve (a fit needs 2 or more).";
  } else {
    caption += "No fitted curve: " + Str(fit, "reason") + ".";
  }
  // The tuned operating point's fit, when its thresholds differ from the ones run.
  const json* tuned_family = tuned != nullptr ? Field(*tuned, family) : nullptr;
  const json* tuned_fit = tuned_family != nullptr ? UsableFit(*tuned_family) : nullptr;
  if (numeric && tuned_differs && tuned_fit != nullptr) {
    std::vector<double> cx, cp;
    if (const json* curve = Field(*tuned_fit, "curve"); curve != nullptr && curve->is_array()) {
      for (const json& c : *curve) {
        if (Num(c, "magnitude") && Num(c, "pod")) cx.push_back(*Num(c, "magnitude")), cp.push_back(*Num(c, "pod"));
      }
    }
    if (!cx.empty()) plot.Line("fitted at the tuned operating point", cx, cp, vega::Stroke{"#000", 1.4, "6 4", 0.8});
  }
  plot.set_caption(caption);
  if (!hx.empty()) plot.Points("runs detected (at 1)", hx, hy, {}, {}, color, vega::Marker::kCircle, htips, 2.2, hruns);
  if (!mx.empty()) plot.Points("runs missed (at 0)", mx, my, {}, {}, "#c62828", vega::Marker::kSquare, mtips, 2.4, mruns);
  plot.Points("detected fraction as run (95 % Wilson)", xs, ys, lo, hi, color, vega::Marker::kCircle, tips, 4.5);
  return plot.Render();
}

}  // namespace

std::vector<std::vector<std::string>> A90Rows(const ReportData& d) {
  const json* tuned = d.tuning ? Field(*d.tuning, "detection_probability") : nullptr;
  std::vector<std::vector<std::string>> rows;
  for (const auto& [family, p] : d.pod) {
    const bool numeric = !p.magnitude_key.empty() && !p.by_magnitude.empty();
    const json fit = AsRunFit(p);
    const json* usable = fit.is_object() && fit.value("ok", false) ? &fit : nullptr;
    const json* tuned_family = tuned != nullptr ? Field(*tuned, family) : nullptr;
    const json* tuned_fit = tuned_family != nullptr ? UsableFit(*tuned_family) : nullptr;
    const std::string key = numeric ? p.magnitude_key : p.name_key;
    rows.push_back({family, key.empty() ? "–" : key, A90Cell(usable, "a90", numeric), A90Cell(usable, "a90_95", numeric),
                    d.tuning ? A90Cell(tuned_fit, "a90", numeric) : "no tuning",
                    d.tuning ? A90Cell(tuned_fit, "a90_95", numeric) : "no tuning"});
  }
  return rows;
}

std::string PodSection(const ReportData& d) {
  std::string o = "<section id=\"pod\"><h2>Detection probability against fault magnitude</h2>";
  if (d.pod.empty()) {
    return o + "<p class=\"missing\">No detection-probability plots: results.jsonl holds no completed faulty runs.</p>"
               "</section>";
  }
  const json* tuned = d.tuning ? Field(*d.tuning, "detection_probability") : nullptr;
  const bool tuned_differs = d.tuning && OperatingPointDiffers(*d.tuning);
  o += "<p>Every faulty run as it was run, with the campaign's own thresholds: small dots at 1 were detected, at 0 "
       "missed (hover for the run). Circles: the detected fraction at each magnitude with its 95 % Wilson score "
       "interval. Line and band: a logistic fit of detection against log severity with its 95 % confidence band "
       "(MIL-HDBK-1823A hit/miss, Firth); a90 and a90/95 where the fit and its one-sided 95 % lower bound reach "
       "90 %, never extrapolated. ";
  if (!d.tuning) {
    o += "No tuned curve: " + CodeSpans(d.tuning_source) + ".";
  } else if (tuned_differs) {
    o += "Dashed: the fit at the tuned operating point (tuning.json), which uses other thresholds.";
  } else {
    o += "The tuned operating point uses the thresholds as run: its curve is this one.";
  }
  o += "</p><div class=\"plots\">";
  bool any_curve_possible = false;
  for (const auto& [family, p] : d.pod) {
    bool fit_possible = false;
    o += PodFamilyPlot(family, p, tuned, tuned_differs, &fit_possible);
    any_curve_possible = any_curve_possible || fit_possible;
  }
  o += "</div>";
  if (!any_curve_possible) {
    o += "<p class=\"missing\">No family had more than one magnitude: no detection-probability curve could be "
         "fitted. Sweep a magnitude (a list or grid of kt_factor, friction_factor, …) to get one.</p>";
  }
  std::vector<std::vector<std::string>> rows;
  for (const auto& r : A90Rows(d)) {
    std::vector<std::string> row;
    for (const std::string& c : r) row.push_back(Escape(c));
    rows.push_back(row);
  }
  o += "<h3>Smallest reliably detected fault</h3>" +
       HtmlTable({"family", "magnitude", "a90 as run", "a90/95 as run", "a90 at the operating point",
                  "a90/95 at the operating point"},
                 rows) +
       "<p class=\"note\">a90: the magnitude detected with 90 % probability (fitted curve); a90/95: with 90 % "
       "probability at 95 % confidence (one-sided lower bound); \"not reached\": not within the tested magnitudes.</p>";
  return o + "</section>";
}


std::string BoundarySection(const ReportData& d) {
  const json& b = *d.boundary;
  std::string o = "<section id=\"boundary\"><h2>Detection boundary (armfault boundary)</h2>";
  const double target = Num(b, "target").value_or(0.9), confidence = Num(b, "confidence").value_or(0.95);
  o += "<p>Each cell (trajectory, fault entry, joint) from " + std::to_string(Count(b, "runs")) + " runs in " +
       std::to_string(Count(b, "batches")) + " batches: every run as a dot at 1 (detected) or 0 (missed), a logistic fit "
       "of detection against log severity (Firth) with its one-sided " + Pct(confidence, 0) +
       " bounds, and the boundary a" + Fixed(100 * target, 0) + "/" + Fixed(100 * confidence, 0) +
       " where the lower bound reaches " + Pct(target, 0) + " (never extrapolated beyond the magnitudes run).</p>";
  o += "<div class=\"plots\">";
  std::vector<std::vector<std::string>> rows;
  auto cell_text = [](const json& x) { return x.is_number() ? Sig4(x.get<double>()) : std::string("–"); };
  const json* cells = Field(b, "cells");
  for (size_t k = 0; cells != nullptr && cells->is_array() && k < cells->size(); ++k) {
    const json& c = (*cells)[k];
    const std::string family = Str(c, "family"), key = Str(c, "magnitude_key");
    const std::string title = Str(c, "trajectory") + ": " + family + ", joint " + std::to_string(Count(c, "joint"));
    const std::string color = FamilyColor(family);
    vega::Plot plot("boundary-" + std::to_string(k), title, kHalfWidth, 340);
    plot.y().label = "detection probability";
    plot.y().min = 0;
    plot.y().max = 1;
    plot.x().label = WithUnit(key) + ", fault magnitude";
    plot.x().reversed = FaultSeverity(key, 2.0) < FaultSeverity(key, 1.0);
    std::vector<double> hx, hy, mx, my;
    std::vector<std::string> htips, mtips;
    std::map<double, int> stack;
    if (const json* points = Field(c, "points"); points != nullptr && points->is_array()) {
      for (const json& p : *points) {
        if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_boolean()) continue;
        const double m = p[0].get<double>();
        const int n = stack[m]++;
        if (p[1].get<bool>()) {
          hx.push_back(m), hy.push_back(1 - 0.014 * (n % 5)), htips.push_back(key + " = " + Sig4(m) + ": detected");
        } else {
          mx.push_back(m), my.push_back(0.014 * (n % 5)), mtips.push_back(key + " = " + Sig4(m) + ": missed");
        }
      }
    }
    const json* fit = Field(c, "fit");
    std::string caption = std::to_string(Count(c, "runs")) + " runs, " + std::to_string(Count(c, "detected")) +
                          " detected; " + Str(c, "status") + ": " + Str(c, "reason") + ".";
    if (fit != nullptr && fit->value("ok", false) && Field(*fit, "curve") && (*fit)["curve"].is_array()) {
      std::vector<double> cx, cp, cl, ch;
      for (const json& p : (*fit)["curve"]) {
        cx.push_back(p["magnitude"].get<double>());
        cp.push_back(p["pod"].get<double>());
        cl.push_back(p["low"].get<double>());
        ch.push_back(p["high"].get<double>());
      }
      plot.Band("one-sided bounds", cx, cl, ch, color, 0.18);
      plot.Line("fit", cx, cp, vega::Stroke{color, 2, "", 1});
    } else {
      caption += " No fitted curve" + (fit != nullptr && Field(*fit, "reason") ? ": " + Str(*fit, "reason") : std::string()) + ".";
    }
    plot.HLine(target, Pct(target, 0), vega::Stroke{"#666", 1, "4 3", 1});
    if (const auto a = Num(c, "a90")) plot.VLine(*a, "a90 = " + Sig4(*a), vega::Stroke{"#333", 1.4, "", 1});
    if (const auto a = Num(c, "a90_95")) {
      plot.VLine(*a, "boundary a90/95 = " + Sig4(*a), vega::Stroke{"#b00020", 2, "5 3", 1});
    } else {
      caption += " No boundary within the magnitudes run.";
    }
    if (!hx.empty()) plot.Points("runs detected (at 1)", hx, hy, {}, {}, color, vega::Marker::kCircle, htips, 2.2);
    if (!mx.empty()) plot.Points("runs missed (at 0)", mx, my, {}, {}, "#c62828", vega::Marker::kSquare, mtips, 2.4);
    plot.set_caption(caption);
    o += plot.Render();
    const json* interval = Field(c, "interval");
    rows.push_back({Escape(Str(c, "trajectory")), Escape(family), std::to_string(Count(c, "joint")), Escape(key),
                    cell_text(c.value("a90_95", json())), cell_text(c.value("a90", json())),
                    interval != nullptr && interval->is_array() && interval->size() == 2
                        ? "[" + cell_text((*interval)[0]) + ", " + cell_text((*interval)[1]) + "]"
                        : "–",
                    std::to_string(Count(c, "runs")), Escape(Str(c, "status"))});
  }
  o += "</div>";
  o += HtmlTable({"trajectory", "family", "joint", "magnitude", "boundary a90/95", "a90", "interval of a90", "runs",
                  "status"},
                 rows);
  return o + "</section>";
}

}  // namespace armfault::report
