#include "reports/campaign_report.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>

#include "campaigns/campaign_summary.h"
#include "campaigns/provenance.h"
#include "campaigns/runner.h"
#include "campaigns/tuning.h"
#include "core/base/json_input.h"
#include "core/monitors/power_monitor.h"
#include "core/observe.h"
#include "reports/svg_plot.h"

namespace armfault {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using svg::Escape;
using svg::Fixed;

// ---------------------------------------------------------------------------------------
// Lenient JSON access: the report shows what is there and says what is not, it does not
// validate (the writers of these files do).

const json* Field(const json& j, const std::string& key) {
  if (!j.is_object()) return nullptr;
  auto it = j.find(key);
  if (it == j.end() || it->is_null()) return nullptr;
  return &*it;
}

std::optional<double> Num(const json& j, const std::string& key) {
  const json* f = Field(j, key);
  if (f != nullptr && f->is_number()) return f->get<double>();
  return std::nullopt;
}

std::string Str(const json& j, const std::string& key) {
  const json* f = Field(j, key);
  return f != nullptr && f->is_string() ? f->get<std::string>() : "";
}

long Count(const json& j, const std::string& key) {
  const json* f = Field(j, key);
  return f != nullptr && f->is_number() ? f->get<long>() : 0;
}

// A rate with its 95 % Wilson interval, from summary.json ({rate, low, high, successes,
// trials}) or tuning.json ({value, low, high, count, runs}).
struct Rate {
  bool present = false;
  std::optional<double> value;
  double low = 0, high = 1;
  long k = 0, n = 0;
};

Rate SummaryRate(const json* j) {
  Rate r;
  if (j == nullptr || !j->is_object()) return r;
  r.present = true;
  r.n = Count(*j, "trials");
  r.k = Count(*j, "successes");
  if (r.n > 0) r.value = Num(*j, "rate");
  r.low = Num(*j, "low").value_or(0);
  r.high = Num(*j, "high").value_or(1);
  return r;
}

Rate TuningRate(const json* j) {
  Rate r;
  if (j == nullptr || !j->is_object()) return r;
  r.present = true;
  r.value = Num(*j, "value");
  r.low = Num(*j, "low").value_or(0);
  r.high = Num(*j, "high").value_or(1);
  r.k = Count(*j, "count");
  r.n = Count(*j, "runs");
  return r;
}

// A fitted magnitude to 4 significant digits: the fit is not more precise than that.
std::string Sig4(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", x);
  return buf;
}

std::string Pct(double x, int decimals = 1) { return Fixed(100 * x, decimals) + " %"; }

std::string RateText(const Rate& r) {
  if (!r.present) return "–";
  if (!r.value) return "no runs";
  return Pct(*r.value) + " [" + Fixed(100 * r.low, 1) + ", " + Fixed(100 * r.high, 1) + "] (" + std::to_string(r.k) +
         "/" + std::to_string(r.n) + ")";
}

std::string SecondsText(std::optional<double> s) { return s ? Fixed(*s, 3) + " s" : "–"; }

// Fixed colours per family, so a family looks the same in every plot.
std::string FamilyColor(const std::string& family) {
  static const std::map<std::string, std::string> colors = {
      {"kt_degradation", "#1f77b4"},      {"friction_increase", "#ff7f0e"}, {"brake_lock", "#2ca02c"},
      {"torque_sensor_stuck", "#d62728"}, {"inverter_short", "#9467bd"},    {"winding_resistance", "#8c564b"},
      {"torque_sensor_drift", "#e377c2"}, {"overall", "#222222"},          {"healthy", "#7f7f7f"}};
  auto it = colors.find(family);
  if (it != colors.end()) return it->second;
  static const char* const spare[] = {"#bcbd22", "#17becf", "#7f7f7f", "#393b79", "#637939"};
  size_t h = 0;
  for (char c : family) h = h * 31 + static_cast<unsigned char>(c);
  return spare[h % 5];
}

// Ids in the page: family names are plain, but keep any text safe for an id.
std::string IdPart(const std::string& s) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) || c == '_' ? c : '-';
  return out;
}

// A setting {"kt_factor.worn": 0.95, ...} as "kt_factor.worn = 0.95, ...".
std::string SettingText(const json* setting) {
  if (setting == nullptr || !setting->is_object()) return "";
  std::string s;
  for (const auto& [key, value] : setting->items()) {
    s += (s.empty() ? "" : ", ") + key + " = " + (value.is_number() ? FormatNumber(value.get<double>()) : value.dump());
  }
  return s;
}

std::string RuleText(const json* rule) {
  if (rule == nullptr || !rule->is_object()) return "";
  std::string s = Str(*rule, "name"), extra;
  for (const auto& [key, value] : rule->items()) {
    if (key == "name") continue;
    extra += (extra.empty() ? "" : ", ") + key + " = " + (value.is_number() ? FormatNumber(value.get<double>()) : value.dump());
  }
  return extra.empty() ? s : s + " (" + extra + ")";
}

// A detection-probability fit that was made: present and not marked "ok": false.
const json* UsableFit(const json& family) {
  const json* fit = Field(family, "fit");
  if (fit == nullptr || !fit->is_object()) return nullptr;
  const json* ok = Field(*fit, "ok");
  return ok != nullptr && ok->is_boolean() && !ok->get<bool>() ? nullptr : fit;
}

// ---------------------------------------------------------------------------------------
// HTML and Markdown tables. HTML cells are given already escaped (they may hold markup).

std::string HtmlTable(const std::vector<std::string>& head, const std::vector<std::vector<std::string>>& rows,
                      const std::string& cls = "") {
  std::string o = "<table" + (cls.empty() ? "" : " class=\"" + cls + "\"") + "><thead><tr>";
  for (const std::string& h : head) o += "<th>" + h + "</th>";
  o += "</tr></thead><tbody>";
  for (const auto& row : rows) {
    o += "<tr>";
    for (const std::string& c : row) o += "<td>" + c + "</td>";
    o += "</tr>";
  }
  return o + "</tbody></table>";
}

std::string MdCell(const std::string& s) {
  std::string out;
  for (char c : s) out += c == '|' ? std::string("\\|") : c == '\n' ? std::string(" ") : std::string(1, c);
  return out;
}

std::string MdTable(const std::vector<std::string>& head, const std::vector<std::vector<std::string>>& rows) {
  std::string o = "|";
  for (const std::string& h : head) o += " " + MdCell(h) + " |";
  o += "\n|";
  for (size_t k = 0; k < head.size(); ++k) o += k == 0 ? "---|" : "---:|";
  o += "\n";
  for (const auto& row : rows) {
    o += "|";
    for (const std::string& c : row) o += " " + MdCell(c) + " |";
    o += "\n";
  }
  return o;
}

std::string VerdictHtml(bool met) {
  return met ? "<span class=\"met\">met</span>" : "<span class=\"missed\">MISSED</span>";
}

// Text with `commands` in backticks as HTML: escaped, the commands in <code>.
std::string CodeSpans(const std::string& text) {
  std::string o;
  bool in_code = false;
  size_t from = 0;
  for (size_t at = text.find('`'); at != std::string::npos; at = text.find('`', from)) {
    o += Escape(text.substr(from, at - from)) + (in_code ? "</code>" : "<code>");
    in_code = !in_code;
    from = at + 1;
  }
  o += Escape(text.substr(from));
  return in_code ? o + "</code>" : o;
}

// A section that needs tuning results and has none: why, and what to run.
std::string TuneFirst(const ReportData& d) {
  return "<p class=\"missing\">No tuning results: " + CodeSpans(d.tuning_source) + ".</p>";
}

// The unit of a fault magnitude or a monitor threshold ("kt_factor", "kt_factor.worn"), for
// axis labels (docs/faults.md, docs/monitor.md); "" when unknown.
std::string UnitOf(std::string key) {
  const std::string worn = ".worn";
  if (key.size() > worn.size() && key.compare(key.size() - worn.size(), worn.size(), worn) == 0) {
    key.resize(key.size() - worn.size());
  }
  static const std::map<std::string, std::string> units = {
      {"kt_factor", "× nominal K_T"},
      {"friction_factor", "× nominal friction"},
      {"resistance_factor", "× nominal winding resistance"},
      {"drag_fraction", "× brake holding torque"},
      {"resistance_ohm", "Ω"},
      {"drift_Nm_per_s", "N m/s"},
      {"sensor_drift_Nm", "N m"},
      {"significance", "standard errors"},
      {"lead", "named"},
      {"kind", "named"}};
  auto it = units.find(key);
  return it == units.end() ? "" : it->second;
}

std::string WithUnit(const std::string& key) {
  const std::string unit = UnitOf(key);
  return unit.empty() ? key : key + " (" + unit + ")";
}

// One sentence per metric, for the page, report.md and docs/campaign-format.md ("Metrics").
const std::vector<std::pair<std::string, std::string>>& MetricDefinitions() {
  static const std::vector<std::pair<std::string, std::string>> defs = {
      {"detection rate",
       "the fraction of faulty runs in which the monitor alarmed at or after the fault's onset, with its 95 % "
       "Wilson score interval."},
      {"false-alarm rate",
       "the fraction of healthy (fault-free) runs in which the monitor alarmed at all, with its 95 % Wilson score "
       "interval."},
      {"alarm-before-onset rate",
       "the fraction of faulty runs that alarmed before their fault began (a false alarm on a faulty run; a "
       "family's false_alarm_rate floor measures it), with its 95 % Wilson score interval."},
      {"isolation accuracy",
       "the fraction of detected faulty runs whose diagnosis named both the right fault family and the right joint, "
       "with its 95 % Wilson score interval."},
      {"latency median / p95",
       "the time from a fault's onset to its first alarm over the detected faulty runs (s), as the median (the mean "
       "of the two middle values for an even count) and the 95th percentile (nearest rank); missed runs are counted "
       "apart, not as long latencies, and there is no confidence interval."},
      {"magnitude error",
       "|estimate − true| / |true| of the fault's sizing parameter over detected, correctly isolated runs whose "
       "monitor estimated that same parameter, as mean and maximum (no confidence interval)."},
      {"95 % Wilson score interval",
       "the [low, high] beside a rate: the true rates consistent with the observed successes out of trials at 95 % "
       "confidence; it stays within [0, 1] and is wide for few runs (0 of 10 still allows up to 27.8 %)."}};
  return defs;
}

// One faulty run's outcome into its family's detection as run.
void AddPodRun(const RunRecord& r, PodAsRun* p) {
  PodAsRun::Cell* cell = nullptr;
  if (!r.magnitude_key.empty()) {
    p->magnitude_key = r.magnitude_key;
    cell = &p->by_magnitude[r.magnitude];
    const double severity = PodSeverity(r.magnitude_key, r.magnitude);
    if (severity > 0 && std::isfinite(severity)) {
      p->severities.push_back(severity);
      p->hits.push_back(r.detected);
    }
  } else {
    if (p->name_key.empty() && r.fault.is_object()) {
      for (const char* key : {"lead", "kind"}) {
        if (r.fault.contains(key) && r.fault[key].is_string()) {
          p->name_key = key;
          break;
        }
      }
    }
    cell = &p->by_name[PodCategory(r.fault)];
  }
  ++cell->runs;
  cell->detected += r.detected ? 1 : 0;
  std::vector<std::string>& ids = r.detected ? cell->hit_ids : cell->miss_ids;
  if (ids.size() < PodAsRun::kMaxListed) ids.push_back(r.run_id);
}

// ---------------------------------------------------------------------------------------
// Small statistics.

double Quantile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return std::nan("");
  const double h = (static_cast<double>(sorted.size()) - 1) * p;
  const size_t i = static_cast<size_t>(std::floor(h));
  const size_t j = std::min(i + 1, sorted.size() - 1);
  return sorted[i] + (h - static_cast<double>(i)) * (sorted[j] - sorted[i]);
}

// Keeps at most about `max_points` of a dense series by taking each bucket's minimum and
// maximum in time order, so spikes survive the thinning.
void Thin(const std::vector<double>& t, const std::vector<double>& y, size_t max_points, std::vector<double>* xs,
          std::vector<double>* ys) {
  const size_t n = std::min(t.size(), y.size());
  const size_t bucket = std::max<size_t>(1, (2 * n + max_points - 1) / std::max<size_t>(2, max_points));
  for (size_t b = 0; b < n; b += bucket) {
    const size_t e = std::min(n, b + bucket);
    size_t lo = b, hi = b;
    for (size_t k = b; k < e; ++k) {
      if (y[k] < y[lo]) lo = k;
      if (y[k] > y[hi]) hi = k;
    }
    xs->push_back(t[std::min(lo, hi)]);
    ys->push_back(y[std::min(lo, hi)]);
    if (lo != hi) {
      xs->push_back(t[std::max(lo, hi)]);
      ys->push_back(y[std::max(lo, hi)]);
    }
  }
}

// ---------------------------------------------------------------------------------------
// Sections.

constexpr int kHalfWidth = 615;   // two plots side by side
constexpr int kFullWidth = 1250;  // one plot across the page

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
       CodeSpans(d.tuning_source) + ".</p>";
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
  return o + "</div></section>";
}

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

  // The marked points: the thresholds as run, the operating point over every run and, when
  // it was chosen on one half, on each half.
  struct Mark {
    std::string label, color;
    svg::Marker marker;
    double size;
    const json* point;
  };
  std::vector<Mark> marks = {{"thresholds as run", "#888888", svg::Marker::kTriangle, 5, Field(*d.tuning, "default_point")},
                             {"operating point (all runs)", "#000000", svg::Marker::kDiamond, 6,
                              Field(*d.tuning, "operating_point")}};
  const json* selection = Field(*d.tuning, "selection");
  if (selection != nullptr) {
    marks.push_back({"operating point on the runs it was chosen on", "#1a7f37", svg::Marker::kDiamond, 4,
                     Field(*selection, "chosen_on")});
    marks.push_back({"operating point on the held-out runs", "#b00020", svg::Marker::kDiamond, 4,
                     Field(*selection, "held_out")});
  }
  std::vector<std::pair<Mark, std::pair<double, double>>> placed;
  for (const Mark& m : marks) {
    if (m.point == nullptr) continue;
    const Rate fa = TuningRate(Field(*m.point, "false_alarm_rate")), det = TuningRate(Field(*m.point, "detection_rate"));
    if (fa.value && det.value) placed.push_back({m, {*fa.value, *det.value}});
  }

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
  auto draw = [&](const std::string& id, const std::string& title, double x_max, const std::string& caption) {
    svg::Plot plot(id, title, kFullWidth, 430);
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
      plot.Line("", xs, ys, svg::Stroke{color, v.overall ? 2.6 : 1.6, "", 0.9});
      plot.Points(label, v.fa, v.det, {}, {}, color, v.overall ? svg::Marker::kCircle : svg::Marker::kSquare, v.tips,
                  v.overall ? 3.2 : 2.8);
    }
    for (const auto& [m, p] : placed) {
      plot.Points(m.label, {p.first}, {p.second}, {}, {}, m.color, m.marker,
                  {m.label + ": false alarms " + Pct(p.first) + ", detection " + Pct(p.second) + "; " +
                   SettingText(Field(*m.point, "setting"))},
                  m.size);
    }
    return plot.Render();
  };
  const double x_max = axis_end(fa_max);
  std::string plots = draw("roc", "Detection against false alarms, per threshold setting", x_max,
                           std::string(x_max < 1 ? "False-alarm axis zoomed to 0 to " : "False-alarm axis 0 to ") +
                               FormatNumber(x_max) + " (largest measured: " + FormatNumber(fa_max) +
                               "). Each point is one threshold setting; lines join measured points only.");
  // When the curves reach far, a second plot zooms on the low end where the operating point
  // lies (up to a little above it and the rule's ceiling); the points beyond are cut off.
  const double low_max = axis_end(std::max(marked_max, ceiling));
  if (low_max <= x_max / 4) {
    long beyond = 0, within = 0;
    for (const RocView& v : swept) {
      for (double x : v.fa) (x > low_max ? beyond : within) += 1;
    }
    if (within > 0 && beyond > 0) {
      plots += draw("roc-low-false-alarms", "The low false-alarm end, where the operating point lies", low_max,
                    "Zoomed to false alarms 0 to " + FormatNumber(low_max) + ": " + std::to_string(beyond) +
                        " points lie beyond the axis (see the plot above).");
    }
  }
  return o + "<div class=\"plots\">" + plots + "</div><ul class=\"note\">" + notes + "</ul></section>";
}

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

// One row per family: family, magnitude, a90 and a90/95 as run, and at the tuned operating
// point (tuning.json's fit).
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
    const std::string color = FamilyColor(family);
    const bool numeric = !p.magnitude_key.empty() && !p.by_magnitude.empty();
    const std::string key = numeric ? p.magnitude_key : p.name_key;
    svg::Plot plot("pod-" + IdPart(family), family, kHalfWidth, 340);
    plot.y().label = "detection probability (fraction of runs)";
    plot.y().min = 0;
    plot.y().max = 1;
    plot.x().label = numeric ? WithUnit(key) + ", fault magnitude"
                             : (key.empty() ? std::string("fault (no magnitude)") : key + " (named fault variant)");
    std::vector<double> xs, ys, lo, hi, hx, hy, mx, my;
    std::vector<std::string> tips, htips, mtips, categories;
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
        htips.push_back(c.hit_ids[i] + ": detected");
      }
      for (size_t i = 0; i < c.miss_ids.size(); ++i) {
        mx.push_back(x);
        my.push_back(0.014 * static_cast<double>(i % 5));
        mtips.push_back(c.miss_ids[i] + ": missed");
      }
      capped = capped || c.hit_ids.size() < static_cast<size_t>(c.detected) ||
               c.miss_ids.size() < static_cast<size_t>(c.runs - c.detected);
    };
    if (numeric) {
      for (const auto& [m, c] : p.by_magnitude) add_cell(m, FormatNumber(m), c);
      // Severity grows to the right: a falling parameter (kt_factor, resistance_ohm) gets a reversed axis.
      plot.x().reversed = PodSeverity(key, 2.0) < PodSeverity(key, 1.0);
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
    any_curve_possible = any_curve_possible || !fit.is_null();
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
      plot.Line("fitted as run", cx, cp, svg::Stroke{color, 2, "", 1});
      plot.HLine(0.9, "90 %", svg::Stroke{"#666", 1, "4 3", 1});
      if (const json* a = Field(*usable, "a90"); a != nullptr && Num(*a, "magnitude")) {
        plot.VLine(*Num(*a, "magnitude"), "a90 = " + Sig4(*Num(*a, "magnitude")), svg::Stroke{"#333", 1.4, "", 1});
      }
      if (const json* a = Field(*usable, "a90_95"); a != nullptr && Num(*a, "magnitude")) {
        plot.VLine(*Num(*a, "magnitude"), "a90/95 = " + Sig4(*Num(*a, "magnitude")),
                   svg::Stroke{"#b00020", 1.4, "5 3", 1});
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
      if (!cx.empty()) plot.Line("fitted at the tuned operating point", cx, cp, svg::Stroke{"#000", 1.4, "6 4", 0.8});
    }
    plot.set_caption(caption);
    if (!hx.empty()) plot.Points("runs detected (at 1)", hx, hy, {}, {}, color, svg::Marker::kCircle, htips, 2.2);
    if (!mx.empty()) plot.Points("runs missed (at 0)", mx, my, {}, {}, "#c62828", svg::Marker::kSquare, mtips, 2.4);
    plot.Points("detected fraction as run (95 % Wilson)", xs, ys, lo, hi, color, svg::Marker::kCircle, tips, 4.5);
    o += plot.Render();
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

// Only with DIR/boundary.json (`armfault boundary`): each cell's runs, fit and boundary.
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
    svg::Plot plot("boundary-" + std::to_string(k), title, kHalfWidth, 340);
    plot.y().label = "detection probability";
    plot.y().min = 0;
    plot.y().max = 1;
    plot.x().label = WithUnit(key) + ", fault magnitude";
    plot.x().reversed = PodSeverity(key, 2.0) < PodSeverity(key, 1.0);
    std::vector<double> hx, hy, mx, my;
    std::map<double, int> stack;
    if (const json* points = Field(c, "points"); points != nullptr && points->is_array()) {
      for (const json& p : *points) {
        if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_boolean()) continue;
        const double m = p[0].get<double>();
        const int n = stack[m]++;
        if (p[1].get<bool>()) hx.push_back(m), hy.push_back(1 - 0.014 * (n % 5));
        else mx.push_back(m), my.push_back(0.014 * (n % 5));
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
      plot.Line("fit", cx, cp, svg::Stroke{color, 2, "", 1});
    } else {
      caption += " No fitted curve" + (fit != nullptr && Field(*fit, "reason") ? ": " + Str(*fit, "reason") : std::string()) + ".";
    }
    plot.HLine(target, Pct(target, 0), svg::Stroke{"#666", 1, "4 3", 1});
    if (const auto a = Num(c, "a90")) plot.VLine(*a, "a90 = " + Sig4(*a), svg::Stroke{"#333", 1.4, "", 1});
    if (const auto a = Num(c, "a90_95")) {
      plot.VLine(*a, "boundary a90/95 = " + Sig4(*a), svg::Stroke{"#b00020", 2, "5 3", 1});
    } else {
      caption += " No boundary within the magnitudes run.";
    }
    if (!hx.empty()) plot.Points("runs detected (at 1)", hx, hy, {}, {}, color, svg::Marker::kCircle, {}, 2.2);
    if (!mx.empty()) plot.Points("runs missed (at 0)", mx, my, {}, {}, "#c62828", svg::Marker::kSquare, {}, 2.4);
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
    svg::Plot plot("latency-threshold-" + IdPart(family), family, kHalfWidth, 320);
    plot.x().label = (param.empty() ? std::string("threshold") : WithUnit(param)) + ", threshold";
    plot.y().label = "latency after onset (s)";
    plot.y().include_zero = true;
    const std::string color = FamilyColor(family);
    plot.Line("95th percentile", xs, p95, svg::Stroke{color, 1.6, "5 3", 1}, svg::Marker::kTriangle);
    plot.Line("median", xs, med, svg::Stroke{color, 2.2, "", 1});
    plot.Points("", xs, med, {}, {}, color, svg::Marker::kCircle, tips, 3.5);
    if (setting != nullptr && Num(*setting, param)) {
      plot.VLine(*Num(*setting, param), "operating " + FormatNumber(*Num(*setting, param)),
                 svg::Stroke{"#000", 1.4, "", 1});
    }
    if (auto it = defaults.find(param); it != defaults.end()) {
      plot.VLine(it->second, "as run " + FormatNumber(it->second), svg::Stroke{"#888", 1.4, "4 3", 1});
    }
    o += plot.Render();
  }
  o += "</div>";
  if (!notes.empty()) o += "<ul class=\"note\">" + notes + "</ul>";
  return o + "</section>";
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
  svg::HeatMap h;
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

// The runs scored wrong with why, and the runs that could not be seen, as two tables.
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
  svg::Plot plot("latency-distribution", "Time from onset to first alarm, detected faulty runs", kFullWidth, height);
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
    std::vector<double> v = it->second;
    std::sort(v.begin(), v.end());
    const std::string color = FamilyColor(families[k]);
    const double y = static_cast<double>(k);
    const double q1 = Quantile(v, 0.25), q2 = Quantile(v, 0.5), q3 = Quantile(v, 0.75);
    const double floor_x = plot.x().min.value_or(1e-3);
    auto at = [&](double x) { return std::max(x, floor_x); };
    plot.Line("", {at(v.front()), at(v.back())}, {y, y}, svg::Stroke{color, 1.2, "", 0.8});
    plot.Rect(at(q1), at(q3), y - 0.28, y + 0.28, color, 0.22, color,
              families[k] + ": quartiles " + Fixed(q1, 3) + " to " + Fixed(q3, 3) + " s, median " + Fixed(q2, 3) + " s");
    plot.Line("", {at(q2), at(q2)}, {y - 0.3, y + 0.3}, svg::Stroke{color, 3, "", 1});
    std::vector<double> xs, ys;
    std::vector<std::string> tips;
    // At most kMaxDots dots per family (every k-th of the sorted latencies) keep a big campaign's page small.
    const size_t stride = (v.size() + kMaxDots - 1) / kMaxDots;
    for (size_t i = 0; i < v.size(); i += stride) {
      // Deterministic jitter (golden-ratio sequence) so equal latencies do not hide each other.
      const double jitter = (std::fmod(static_cast<double>(i / stride) * 0.6180339887, 1.0) - 0.5) * 0.4;
      xs.push_back(at(v[i]));
      ys.push_back(y + jitter);
      tips.push_back(families[k] + ": " + Fixed(v[i], 3) + " s");
    }
    plot.Points("", xs, ys, {}, {}, color, svg::Marker::kCircle, tips, 2.6);
  }
  return o + "<div class=\"plots\">" + plot.Render() + "</div></section>";
}

std::string ThesisSection(const ReportData& d) {
  std::string o = "<section id=\"thesis\"><h2>Efficiency against K_T factor (thesis table 5-3)</h2>";
  if (d.table_5_3.empty()) {
    return o + "<p class=\"missing\">No thesis results: " + Escape(d.thesis_source) + " holds no table_5_3 rows.</p></section>";
  }
  svg::Plot plot("thesis-table-5-3", "Top-joint efficiency (eq 5-5) as the torque constant degrades", kHalfWidth, 340);
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
  plot.Line("thesis (published)", xs, thesis, svg::Stroke{"#444", 2, "6 3", 1}, svg::Marker::kSquare);
  plot.Points("", xs, thesis, {}, {}, "#444", svg::Marker::kSquare, ttips, 3.5);
  plot.Line("armfault (simulated)", xs, ours, svg::Stroke{"#1f77b4", 2.2, "", 1}, svg::Marker::kCircle);
  plot.Points("", xs, ours, {}, {}, "#1f77b4", svg::Marker::kCircle, otips, 3.5);
  o += "<div class=\"plots\">" + plot.Render() + "<div class=\"side\">" +
       HtmlTable({"K_T factor", "thesis η (%)", "armfault η (%)", "thesis ratio", "armfault ratio", "windows"}, rows) +
       "<p>Ratio: relative to n = 1. Efficiency: Σ E_out / Σ E_mesh_in over the top joint's forward-flow windows "
       "(docs/monitor.md).</p></div></div>";
  return o + "</section>";
}

std::string RecordText(const RunRecord& r) {
  if (!r.ok) return "failed: " + r.failure_reason;
  if (!r.detected) return "not detected";
  std::string s = "detected at " + Fixed(r.detection_time_s.value_or(0), 3) + " s";
  if (!r.isolated_family.empty()) s += ", isolated " + r.isolated_family + " on joint " + std::to_string(r.isolated_joint);
  if (r.magnitude_estimate) s += ", " + r.magnitude_name + " ≈ " + Fixed(*r.magnitude_estimate, 3);
  return s;
}

std::string RunSection(const ReportData& d) {
  const RunSeries& s = d.run;
  std::string o = "<section id=\"run\"><h2>One run over time</h2>";
  if (!s.error.empty()) {
    return o + "<p class=\"missing\">Could not re-simulate " + Escape(s.run_id.empty() ? "a run" : s.run_id) + ": " +
           Escape(s.error) + "</p></section>";
  }
  const RunRecord& r = s.record;
  o += "<p>Run <code>" + Escape(s.run_id) + "</code> (" + Escape(s.why) + "; choose another with <code>--run "
       "RUN_ID</code>), re-simulated with a second monitor on the same signals.</p>";
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
  const double t_end = s.t_s.empty() ? 1 : s.t_s.back();
  for (size_t k = 0; k < s.joints.size(); ++k) {
    const int j = s.joints[k];
    const std::string jt = "joint " + std::to_string(j);
    auto marks = [&](svg::Plot* p) {
      p->set_min_left(72);  // the three panels share their time axis: line them up
      p->x().label = "time (s)";
      p->x().min = 0;
      p->x().max = t_end;
      if (!r.family.empty()) {
        p->VLine(r.onset_s, "fault onset " + Fixed(r.onset_s, 2) + " s (" + r.family + ")",
                 svg::Stroke{"#d62728", 1.6, "6 3", 1});
      }
      if (s.first_alarm_s) {
        p->VLine(*s.first_alarm_s,
                 "first alarm " + Fixed(*s.first_alarm_s, 2) + " s" +
                     (s.first_alarm_family.empty() ? "" : " (" + s.first_alarm_family + ")"),
                 svg::Stroke{"#000", 1.6, "", 1});
      }
    };
    // Efficiencies per judged window of this joint.
    svg::Plot eff("run-j" + std::to_string(j) + "-efficiency", "Efficiencies of " + jt + " per window", kFullWidth, 320);
    const bool judged = std::any_of(s.monitor.windows.begin(), s.monitor.windows.end(),
                                    [&](const EfficiencyWindow& w) { return w.joint == j && w.used; });
    eff.set_caption(judged ? std::string("Judged windows; bar: the window's span; dashed: what a healthy joint would show "
                                         "for the same motion.") + (s.first_alarm_s ? "" : " No alarm in this run.")
                           : std::string("Empty: the monitor judged no window of this joint (it did not move or carry "
                                         "load enough)."));
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
      eff.Segments(std::string(se.name) + " measured", x0, x1, m, svg::Stroke{se.color, 2.4, "", 1},
                   svg::Marker::kCircle);
      eff.Segments(std::string(se.name) + " healthy", x0, x1, e, svg::Stroke{se.color, 1.6, "5 3", 1},
                   svg::Marker::kNone);
    }
    // Wild ratios (a window right at a fault's onset) are clipped rather than squashing the rest.
    eff.y().min = std::max(-0.5, ymin);
    eff.y().max = std::min(1.5, ymax);
    marks(&eff);

    std::vector<double> tx, ty;
    svg::Plot cur("run-j" + std::to_string(j) + "-current", "Currents of " + jt, kFullWidth, 280);
    cur.y().label = "current (A)";
    Thin(s.t_s, s.i_cmd_A[k], 1400, &tx, &ty);
    cur.Line("commanded current i (after the DAC)", tx, ty, svg::Stroke{"#1f77b4", 1.3, "", 1});
    tx.clear(), ty.clear();
    Thin(s.t_s, s.i_supply_A[k], 1400, &tx, &ty);
    cur.Line("supply current I_d (measured, period mean)", tx, ty, svg::Stroke{"#d62728", 1.1, "", 0.85});
    marks(&cur);

    svg::Plot tor("run-j" + std::to_string(j) + "-torque", "Torque sensor of " + jt, kFullWidth, 260);
    tor.y().label = "torque (N m)";
    tx.clear(), ty.clear();
    Thin(s.t_s, s.tau_sensor_Nm[k], 1400, &tx, &ty);
    tor.Line("torque-sensor reading τ_s", tx, ty, svg::Stroke{"#2ca02c", 1.3, "", 1});
    marks(&tor);
    o += "<div class=\"plots\">" + eff.Render() + cur.Render() + tor.Render() + "</div>";
  }
  return o + "</section>";
}

// Which campaign the page is of, and which files say so.
std::string CampaignHashText(const ReportData& d, bool html) {
  if (d.campaign_hash.empty()) return "No file names its campaign (no campaign_hash: written by an older armfault).";
  std::string files;
  for (size_t k = 0; k < d.hashed_files.size(); ++k) {
    files += (k == 0 ? "" : k + 1 == d.hashed_files.size() ? " and " : ", ") + d.hashed_files[k];
  }
  const std::string hash = html ? "<code>" + Escape(d.campaign_hash) + "</code>" : "`" + d.campaign_hash + "`";
  return "Campaign hash " + hash + " (SHA-256 of the resolved campaign), carried by " + (html ? Escape(files) : files) +
         (d.hashed_files.size() > 1 ? ", which agree." : ".");
}

const char* const kStyle = R"(
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,Arial,sans-serif;color:#222;margin:0;background:#f6f7f9}
main{max-width:1340px;margin:0 auto;padding:12px 16px 40px}
h1{font-size:24px;margin:14px 0 4px}h2{font-size:19px;margin:26px 0 8px;border-bottom:1px solid #ccc;padding-bottom:4px}
h3{font-size:15px;margin:16px 0 6px}
nav a{margin-right:14px;color:#1f4e9c;text-decoration:none}
section{background:#fff;border:1px solid #e2e4e8;border-radius:6px;padding:4px 14px 14px;margin-top:14px}
.tables{display:flex;flex-wrap:wrap;gap:0 28px;align-items:flex-start}
.note{font-size:12px;color:#555;max-width:520px}
.plots{display:flex;flex-wrap:wrap;gap:10px;align-items:flex-start}
svg.plot{background:#fff;border:1px solid #eee;max-width:100%;height:auto}
.side{max-width:620px}
table{border-collapse:collapse;font-size:13px;margin:4px 0 8px}
th,td{border:1px solid #ddd;padding:3px 8px;text-align:left;vertical-align:top}th{background:#f0f2f5}
td+td{font-variant-numeric:tabular-nums}
.kv td:first-child{color:#444}
.met{color:#1a7f37;font-weight:bold}.missed{color:#c62828;font-weight:bold}
.missing{background:#fff4e5;border:1px solid #f0c36d;padding:8px 10px;border-radius:4px}
.swatch{display:inline-block;width:10px;height:10px;margin-right:6px;border-radius:2px}
code{background:#f0f2f5;padding:0 3px;border-radius:3px;font-size:12px}
)";

}  // namespace

std::optional<nlohmann::json> ReadTuning(const std::string& dir) {
  const fs::path path = fs::path(dir) / "tuning.json";
  if (!fs::exists(path)) return std::nullopt;
  return ReadJsonFile(path.string());
}

std::optional<nlohmann::json> TuningOrDefault(const std::string& dir) {
  if (std::optional<nlohmann::json> stored = ReadTuning(dir)) return stored;
  return TuneCampaignDir(dir, TuneOptions()).report;
}

RunSeries SimulateRunSeries(const Campaign& campaign, const CaseSpec& spec) {
  RunSeries s;
  s.run_id = spec.run_id;
  const int joints = static_cast<int>(campaign.robot.modules.size());
  // The faulted joint; for a healthy run, every joint that moves.
  if (!spec.fault.is_null() && spec.fault.contains("joint") && spec.fault["joint"].is_number_integer()) {
    s.joints.push_back(spec.fault["joint"].get<int>());
  } else {
    for (const auto& [joint, trajectory] : campaign.trajectories[spec.trajectory].parsed) s.joints.push_back(joint);
  }
  s.joints.erase(std::remove_if(s.joints.begin(), s.joints.end(), [&](int j) { return j < 1 || j > joints; }),
                 s.joints.end());
  s.i_cmd_A.resize(s.joints.size());
  s.i_supply_A.resize(s.joints.size());
  s.tau_sensor_Nm.resize(s.joints.size());
  // The same model (the unit's, commissioned where the campaign commissions) and the same
  // signals as the run's own monitor: the same output.
  UnitMonitors units(campaign);
  const UnitMonitor unit = units.For(spec);
  const std::unique_ptr<HealthMonitor> monitor = (unit.model ? unit.model : campaign.monitor_model)->NewMonitor();
  double t_last = 0;
  const TickObserver observer = ObserveWith(monitor.get(), [&](const Tick& tick) {
    t_last = tick.t_s;
    s.t_s.push_back(tick.t_s);
    for (size_t k = 0; k < s.joints.size(); ++k) {
      const JointTick& jt = (*tick.joints)[s.joints[k] - 1];
      s.i_cmd_A[k].push_back(jt.signals.i_cmd_A);
      s.i_supply_A[k].push_back(jt.signals.i_supply_meas_A);
      s.tau_sensor_Nm[k].push_back(jt.signals.tau_sensor_Nm);
    }
  });
  s.record = RunCase(campaign, spec, observer, &units);
  monitor->Finish(t_last);
  s.monitor = monitor->output();
  for (const Verdict& v : s.monitor.verdicts) {
    if (v.alarm) {
      s.first_alarm_s = v.t_s;
      s.first_alarm_family = v.family;
      break;
    }
  }
  if (!s.record.ok) s.error = s.record.failure_reason;
  return s;
}

ReportData GatherReportData(const ReportOptions& options) {
  ReportData d;
  d.dir = options.dir;
  const fs::path dir(options.dir);
  const fs::path summary_path = dir / "summary.json";
  if (!fs::exists(summary_path)) {
    throw InputError(summary_path.string(), "", "no such file: run `armfault run CAMPAIGN -o " + options.dir + "` first");
  }
  d.summary = ReadJsonFile(summary_path.string());

  // campaign.json: the campaign every other file must be of, and the one the plotted run is
  // re-simulated from. A campaign that does not parse here (a moved csv trajectory) still
  // names its campaign; only the run section says what went wrong.
  const fs::path campaign_path = dir / "campaign.json";
  std::optional<Campaign> campaign;
  std::string campaign_error;
  std::vector<CampaignClaim> claims;
  if (fs::exists(campaign_path)) {
    const json file = ReadJsonFile(campaign_path.string());
    claims.push_back({campaign_path.string(), ClaimedCampaignHash(file, campaign_path.string()), ""});
    try {
      if (!file.is_object() || !file.contains("campaign")) {
        throw InputError(campaign_path.string(), "", "no \"campaign\" key: not written by `armfault run`");
      }
      // Relative file names (csv trajectories) resolve against DIR: the campaign's own folder is not recorded.
      campaign = CampaignFromJson(file["campaign"], campaign_path.string(), options.dir);
    } catch (const InputError& e) {
      campaign_error = e.what();
    }
  } else {
    campaign_error = campaign_path.string() + ": no such file";
  }
  claims.push_back({summary_path.string(), ClaimedCampaignHash(d.summary, summary_path.string()),
                    "summary.json is stale or was copied from elsewhere: run the campaign into " + options.dir +
                        " again (or merge its shards there)"});
  RequireOneCampaign(claims);
  for (const CampaignClaim& c : claims) {
    if (!c.hash) continue;
    if (d.campaign_hash.empty()) d.campaign_hash = *c.hash;
    d.hashed_files.push_back(fs::path(c.file).filename().string());
  }

  // results.jsonl: latencies and detection as run per family, and the candidates for the
  // plotted run. Each line must be a case of campaign.json.
  std::optional<CaseMatcher> matcher;
  if (campaign) matcher.emplace(*campaign);
  if (campaign) d.not_excited_included = campaign->include_not_excited;
  std::optional<RunRecord> first, first_missed, first_detected, wanted;
  {
    const fs::path path = dir / "results.jsonl";
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path.string(), "", "cannot read the file (run `armfault run` first)");
    std::string line;
    long n = 0;
    while (std::getline(in, line)) {
      ++n;
      if (line.empty()) continue;
      RunRecord r;
      try {
        r = RunRecordFromJson(nlohmann::json::parse(line));
      } catch (const std::exception& e) {
        throw InputError(path.string(), "", "line " + std::to_string(n) + ": " + e.what());
      }
      if (matcher) {
        if (const std::string why = matcher->Mismatch(r); !why.empty()) {
          throw InputError(path.string(), "",
                           "line " + std::to_string(n) + ": " + why + ": this results.jsonl is not a run of " +
                               campaign_path.string() +
                               " (files of different campaigns are not read together); run the campaign into " +
                               options.dir + " again");
        }
      }
      ++d.records;
      if (!first) first = r;
      if (!options.run_id.empty() && r.run_id == options.run_id) wanted = r;
      if (r.ok && !r.miss_reason.empty() && (r.family.empty() || r.excited() || d.not_excited_included)) {
        if (d.wrong.size() < ReportData::kListedRuns) d.wrong.push_back({r.run_id, r.miss_reason});
        ++d.wrong_count;
      }
      if (!r.ok || r.family.empty()) continue;
      if (!r.injected()) continue;  // its onset condition never fired: as summary.json, outside the rates
      if (!r.excited()) {
        if (d.not_excited.size() < ReportData::kListedRuns) d.not_excited.push_back({r.run_id, r.not_excited_reason});
        ++d.not_excited_count;
        if (!d.not_excited_included) continue;  // as summary.json: outside the rates
      }
      if (!r.is_compound()) AddPodRun(r, &d.pod[r.family]);  // no single magnitude to plot against
      if (r.detected) {
        if (r.latency_s && std::isfinite(*r.latency_s)) d.latencies_s[r.family].push_back(*r.latency_s);
        if (!first_detected) first_detected = r;
      } else {
        ++d.misses[r.family];
        if (!first_missed) first_missed = r;
      }
    }
  }

  // Tuning: DIR/tuning.json must be of this campaign; without one, the tuner's defaults.
  const fs::path tuning_path = dir / "tuning.json";
  const bool tuning_file = fs::exists(tuning_path);
  const std::string tune_hint = "run `armfault tune " + options.dir + "`";
  if (options.tuning) {
    try {
      d.tuning = options.tuning(options.dir);
    } catch (const InputError& e) {
      if (tuning_file) throw;
      d.tuning_source = tuning_path.string() + " is absent, and tuning with the defaults failed (" + e.what() + "): " +
                        tune_hint + " with another rule or sweep";
    }
  }
  if (d.tuning) {
    d.tuning_source = tuning_file ? tuning_path.string()
                                  : "computed now with the tuner's defaults (" + tuning_path.string() +
                                        " is absent: " + tune_hint + " to write it or to choose another rule)";
    const std::string name = tuning_file ? tuning_path.string() : "the tuning computed for " + options.dir;
    claims.push_back({name, ClaimedCampaignHash(*d.tuning, name),
                      tune_hint + " to tune this directory's campaign again (it rewrites tuning.json)"});
    RequireOneCampaign(claims);
    if (!d.campaign_hash.empty() && tuning_file) d.hashed_files.push_back("tuning.json");
  } else if (d.tuning_source.empty()) {
    d.tuning_source = tuning_path.string() + " is absent: " + tune_hint;
  }

  // boundary.json (`armfault boundary`): of this campaign too.
  const fs::path boundary_path = dir / "boundary.json";
  if (fs::exists(boundary_path)) {
    json b = ReadJsonFile(boundary_path.string());
    claims.push_back({boundary_path.string(), ClaimedCampaignHash(b, boundary_path.string()),
                      "run `armfault boundary` into " + options.dir + " again (or `armfault boundary --from " +
                          options.dir + "`)"});
    RequireOneCampaign(claims);
    if (!d.campaign_hash.empty()) d.hashed_files.push_back("boundary.json");
    d.boundary = std::move(b);
  }

  // Thesis table 5-3: the directory's own, else simulated.
  const fs::path thesis_path = dir / "thesis.json";
  if (fs::exists(thesis_path)) {
    const json t = ReadJsonFile(thesis_path.string());
    d.thesis_source = thesis_path.string();
    if (const json* rows = Field(t, "table_5_3"); rows != nullptr && rows->is_array()) {
      for (const json& row : *rows) {
        ThesisRow r;
        r.factor = Num(row, "kt_factor").value_or(std::nan(""));
        r.label = "n = " + Fixed(r.factor, 1);
        r.thesis_pct = Num(row, "thesis_pct").value_or(std::nan(""));
        r.armfault_pct = Num(row, "armfault_pct").value_or(std::nan(""));
        r.thesis_ratio = Num(row, "thesis_ratio").value_or(std::nan(""));
        r.armfault_ratio = Num(row, "armfault_ratio").value_or(std::nan(""));
        r.windows = static_cast<int>(Count(row, "windows"));
        r.ok = Field(row, "failure") == nullptr;
        d.table_5_3.push_back(r);
      }
    }
  } else {
    const ThesisResults t = RunThesisExperiments(options.thesis_seed);
    d.thesis_source = "simulated now with seed " + std::to_string(options.thesis_seed) +
                      " (no thesis.json in the directory)";
    if (!t.experiments.empty()) d.table_5_3 = t.experiments[0].rows;
  }

  // The plotted run, re-simulated.
  RunSeries& s = d.run;
  const std::optional<RunRecord>& chosen =
      !options.run_id.empty() ? wanted : first_missed ? first_missed : first_detected ? first_detected : first;
  s.why = !options.run_id.empty() ? "chosen with --run"
          : first_missed          ? "the first faulty run that was missed"
          : first_detected        ? "the first faulty run (every faulty run was detected)"
                                  : "the first run (no faulty runs)";
  s.run_id = !options.run_id.empty() ? options.run_id : chosen ? chosen->run_id : "";
  if (!campaign) {
    if (!options.run_id.empty()) throw InputError("--run", "", "cannot re-simulate: " + campaign_error);
    s.error = campaign_error;
    return d;
  }
  if (s.run_id.empty()) {
    s.error = "results.jsonl holds no runs";
    return d;
  }
  const std::vector<CaseSpec> cases = ExpandCases(*campaign);
  auto it = std::find_if(cases.begin(), cases.end(), [&](const CaseSpec& c) { return c.run_id == s.run_id; });
  if (it == cases.end()) {
    throw InputError("--run", "", "no run \"" + s.run_id + "\" in " + campaign_path.string() +
                                      " (run ids look like \"" + (cases.empty() ? "" : cases.front().run_id) + "\")");
  }
  const std::string why = s.why;
  s = SimulateRunSeries(*campaign, *it);
  s.why = why;
  s.stored = chosen;
  return d;
}

std::string RenderReportHtml(const ReportData& d) {
  const json campaign = Field(d.summary, "campaign") ? d.summary["campaign"] : json::object();
  const std::string name = Str(campaign, "name");
  std::string o = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
                  "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">";
  // The campaign's content hash, also for machines reading the page.
  if (!d.campaign_hash.empty()) o += "<meta name=\"armfault-campaign-hash\" content=\"" + Escape(d.campaign_hash) + "\">";
  o += "<title>armfault report: " + Escape(name) + "</title><style>" + kStyle + "</style></head><body><main>";
  o += "<h1>armfault report: " + Escape(name) + "</h1>";
  const bool met = Field(d.summary, "floors_met") && d.summary["floors_met"].is_boolean() &&
                   d.summary["floors_met"].get<bool>();
  o += "<p>Directory <code>" + Escape(d.dir) + "</code>, armfault " + Escape(Str(d.summary, "armfault_version")) +
       ". Floors: " + (met ? "<span class=\"met\">all met</span>" : "<span class=\"missed\">some MISSED</span>") +
       ". Hover over a point for its numbers.</p>";
  o += "<p>" + CampaignHashText(d, true) + "</p>";
  o += "<nav><a href=\"#summary\">rates and floors</a><a href=\"#operating-point\">operating point</a>"
       "<a href=\"#roc\">ROC</a><a href=\"#pod\">detection probability</a><a href=\"#latency-threshold\">latency vs "
       "threshold</a><a href=\"#confusion\">confusion</a><a href=\"#why\">why wrong</a><a href=\"#latency\">latency</a><a href=\"#thesis\">table "
       "5-3</a><a href=\"#run\">one run</a>" + std::string(d.boundary ? "<a href=\"#boundary\">boundary</a>" : "") + "</nav>";
  o += SummarySection(d);
  o += OperatingPointSection(d);
  o += RocSection(d);
  o += PodSection(d);
  if (d.boundary) o += BoundarySection(d);
  o += LatencyThresholdSection(d);
  o += ConfusionSection(d);
  o += WhySection(d);
  o += LatencyDistributionSection(d);
  o += ThesisSection(d);
  o += RunSection(d);
  o += "</main></body></html>\n";
  return o;
}

std::string RenderReportMarkdown(const ReportData& d) {
  const json empty = json::object();
  const json& s = d.summary;
  const json& campaign = Field(s, "campaign") ? s["campaign"] : empty;
  const json& overall = Field(s, "overall") ? s["overall"] : empty;
  const json& runs = Field(s, "runs") ? s["runs"] : empty;
  std::string md = "# armfault report: " + Str(campaign, "name") + "\n\n";
  md += std::to_string(Count(runs, "total")) + " runs (" + std::to_string(Count(runs, "faulty")) + " faulty, " +
        std::to_string(Count(runs, "healthy")) + " healthy, " + std::to_string(Count(runs, "failed")) +
        " failed). Plots: report.html.\n\n" + CampaignHashText(d, false) + "\n\n";
  const json& latency = Field(overall, "latency") ? overall["latency"] : empty;
  md += MdTable({"metric", "rate [95 % Wilson interval] (successes/trials)"},
                {{"detection", RateText(SummaryRate(Field(overall, "detection")))},
                 {"false alarm", RateText(SummaryRate(Field(overall, "false_alarm")))},
                 {"alarm before onset", RateText(SummaryRate(Field(overall, "alarm_before_onset_rate")))},
                 {"isolation", RateText(SummaryRate(Field(overall, "isolation")))},
                 {"latency median / p95", SecondsText(Num(latency, "median_s")) + " / " + SecondsText(Num(latency, "p95_s"))}});
  md += "\n";
  for (const auto& [name, sentence] : MetricDefinitions()) md += "- **" + name + "**: " + sentence + "\n";

  md += "\n## Operating point\n\n";
  if (!d.tuning) {
    md += "No tuning results: " + d.tuning_source + ".\n";
  } else {
    const json& t = *d.tuning;
    const json& op = Field(t, "operating_point") ? t["operating_point"] : empty;
    md += "Rule: " + RuleText(Field(t, "rule")) + ". Setting: " + SettingText(Field(op, "setting")) + ".\n\n";
    md += MdTable({"metric", "operating point"},
                  {{"detection", RateText(TuningRate(Field(op, "detection_rate")))},
                   {"false alarm", RateText(TuningRate(Field(op, "false_alarm_rate")))},
                   {"isolation", RateText(TuningRate(Field(op, "isolation_accuracy")))},
                   {"latency median / p95",
                    SecondsText(Num(op, "latency_median_s")) + " / " + SecondsText(Num(op, "latency_p95_s"))}});
  }
  md += "\n## Smallest reliably detected fault (a90/95)\n\n";
  const std::vector<std::vector<std::string>> a90 = A90Rows(d);
  md += a90.empty() ? "No completed faulty runs: nothing to fit.\n"
                    : MdTable({"family", "magnitude", "a90 as run", "a90/95 as run", "a90 at the operating point",
                               "a90/95 at the operating point"},
                              a90);
  if (d.boundary) {
    md += "\n## Detection boundary (armfault boundary)\n\n";
    std::vector<std::vector<std::string>> rows;
    auto text = [](const json& x) { return x.is_number() ? Sig4(x.get<double>()) : std::string("–"); };
    if (const json* cells = Field(*d.boundary, "cells"); cells != nullptr && cells->is_array()) {
      for (const json& c : *cells) {
        const json* interval = Field(c, "interval");
        rows.push_back({Str(c, "trajectory"), Str(c, "family"), std::to_string(Count(c, "joint")), Str(c, "magnitude_key"),
                        text(c.value("a90_95", json())), text(c.value("a90", json())),
                        interval != nullptr && interval->is_array() && interval->size() == 2
                            ? "[" + text((*interval)[0]) + ", " + text((*interval)[1]) + "]"
                            : "–",
                        std::to_string(Count(c, "runs")), Str(c, "status")});
      }
    }
    md += MdTable({"trajectory", "family", "joint", "magnitude", "boundary a90/95", "a90", "interval of a90", "runs",
                   "status"},
                  rows);
  }

  md += "\n## Floors\n\n";
  const json* floors = Field(s, "floors");
  if (floors == nullptr || !floors->is_array() || floors->empty()) {
    md += "The campaign sets no floors.\n";
  } else {
    std::vector<std::vector<std::string>> rows;
    for (const json& f : *floors) {
      const bool f_met = Field(f, "met") && f["met"].is_boolean() && f["met"].get<bool>();
      rows.push_back({Str(f, "name"), (Str(f, "kind") == "max" ? "≤ " : "≥ ") + Fixed(Num(f, "bound").value_or(0), 3),
                      Num(f, "measured") ? Fixed(*Num(f, "measured"), 3) : "nothing to measure",
                      f_met ? "met" : "MISSED"});
    }
    md += MdTable({"floor", "bound", "measured", "verdict"}, rows);
  }
  return md;
}

ReportPaths WriteCampaignReport(const ReportOptions& options) {
  const ReportData data = GatherReportData(options);
  ReportPaths paths;
  fs::path html = options.output.empty() ? fs::path(options.dir) / "report.html" : fs::path(options.output);
  fs::path md = html;
  md.replace_extension(".md");
  if (md == html) md += ".md";
  if (html.has_parent_path()) fs::create_directories(html.parent_path());
  WriteAtomically(html, RenderReportHtml(data));
  WriteAtomically(md, RenderReportMarkdown(data));
  paths.html = html.string();
  paths.markdown = md.string();
  return paths;
}

}  // namespace armfault
