#include "reports/campaign_report.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "campaigns/runner.h"
#include "campaigns/tuning.h"
#include "core/json_input.h"
#include "core/power_monitor.h"
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

// a90 or a90_95 of a family as text: the magnitude, "not reached" (inside the tested range)
// or "no fit".
std::string A90Text(const json& family, const char* key, bool with_severity) {
  const json* fit = UsableFit(family);
  if (fit == nullptr) return "no fit";
  const json* v = Field(*fit, key);
  if (v == nullptr || !Num(*v, "magnitude")) return "not reached";
  std::string s = FormatNumber(*Num(*v, "magnitude"));
  if (with_severity && Num(*v, "severity")) s += " (severity " + FormatNumber(*Num(*v, "severity")) + ")";
  return s;
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

std::string TuneFirst(const std::string& dir) {
  return "<p class=\"missing\">No tuning results (<code>" + Escape((fs::path(dir) / "tuning.json").string()) +
         "</code> is missing): run <code>armfault tune " + Escape(dir) + "</code> first.</p>";
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
    o += "<p>No faulty runs.</p>";
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
  return o + "</section>";
}

std::string OperatingPointSection(const ReportData& d) {
  std::string o = "<section id=\"operating-point\"><h2>Operating point</h2>";
  if (!d.tuning) return o + TuneFirst(d.dir) + "</section>";
  const json& t = *d.tuning;
  const json empty = json::object();
  const json& op = Field(t, "operating_point") ? t["operating_point"] : empty;
  const json& def = Field(t, "default_point") ? t["default_point"] : empty;
  o += "<p>Chosen by the rule <b>" + Escape(RuleText(Field(t, "rule"))) + "</b> among " +
       std::to_string(Count(t, "settings")) + " threshold settings scored on this campaign's runs.</p>";
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
  if (!rows.empty()) o += "<div><h3>Thresholds</h3>" + HtmlTable({"threshold", "operating point", "default"}, rows) + "</div>";
  auto lat = [](const json& p, const char* key) { return Escape(SecondsText(Num(p, key))); };
  std::vector<std::vector<std::string>> rates = {
      {"detection rate", Escape(RateText(TuningRate(Field(op, "detection_rate")))),
       Escape(RateText(TuningRate(Field(def, "detection_rate"))))},
      {"false-alarm rate", Escape(RateText(TuningRate(Field(op, "false_alarm_rate")))),
       Escape(RateText(TuningRate(Field(def, "false_alarm_rate"))))},
      {"isolation accuracy", Escape(RateText(TuningRate(Field(op, "isolation_accuracy")))),
       Escape(RateText(TuningRate(Field(def, "isolation_accuracy"))))},
      {"latency median", lat(op, "latency_median_s"), lat(def, "latency_median_s")},
      {"latency p95", lat(op, "latency_p95_s"), lat(def, "latency_p95_s")}};
  o += "<div><h3>Rates</h3>" + HtmlTable({"metric", "operating point", "default thresholds"}, rates) + "</div></div>";
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
  // a90 and a90/95.
  if (const json* pod = Field(t, "detection_probability"); pod != nullptr && pod->is_object() && !pod->empty()) {
    std::vector<std::vector<std::string>> arows;
    for (const auto& [family, f] : pod->items()) {
      arows.push_back({Escape(family), Escape(Str(f, "magnitude_key")), Escape(A90Text(f, "a90", true)),
                       Escape(A90Text(f, "a90_95", true))});
    }
    o += "<div><h3>Smallest reliably detected fault</h3>" + HtmlTable({"family", "magnitude", "a90", "a90/95"}, arows) +
         "<p class=\"note\">a90: the magnitude detected with 90 % probability (fitted curve); a90/95: with 90 % "
         "probability at 95 % confidence (lower band); \"not reached\": not within the tested magnitudes.</p></div>";
  }
  return o + "</div></section>";
}

std::string RocSection(const ReportData& d) {
  std::string o = "<section id=\"roc\"><h2>ROC curves</h2>";
  if (!d.tuning) return o + TuneFirst(d.dir) + "</section>";
  const json* roc = Field(*d.tuning, "roc");
  if (roc == nullptr || !roc->is_object() || roc->empty()) return o + "<p>tuning.json has no ROC curves.</p></section>";
  double fa_max = 0;
  for (const auto& [name, curve] : roc->items()) {
    if (const json* pts = Field(curve, "points"); pts != nullptr && pts->is_array()) {
      for (const json& p : *pts) fa_max = std::max(fa_max, Num(p, "false_alarm_rate").value_or(0));
    }
  }
  svg::Plot plot("roc", "Detection against false alarms, per threshold setting", kFullWidth, 430);
  const bool zoom = fa_max <= 0.5;
  plot.set_caption(fa_max == 0 ? "No threshold setting raised a false alarm on this campaign's healthy runs: every "
                                 "point sits at 0 (more healthy runs would separate them)."
                   : zoom        ? "False-alarm axis zoomed to the measured range; each point is one threshold setting."
                                 : "Each point is one threshold setting; dotted: chance.");
  plot.x().label = "false-alarm rate (alarmed healthy runs / healthy runs)";
  plot.x().min = 0;
  plot.x().max = zoom ? std::optional<double>() : std::optional<double>(1.0);
  if (zoom && fa_max == 0) plot.x().max = 0.05;
  plot.y().label = "detection rate (detected / faulty runs)";
  plot.y().min = 0;
  plot.y().max = 1;
  if (!zoom) plot.Line("", {0, 1}, {0, 1}, svg::Stroke{"#999", 1, "2 3", 1});
  auto draw = [&](const std::string& name, const json& curve, bool overall) {
    std::vector<double> xs, ys;
    std::vector<std::string> tips;
    if (const json* pts = Field(curve, "points"); pts != nullptr && pts->is_array()) {
      for (const json& p : *pts) {
        const auto fa = Num(p, "false_alarm_rate"), det = Num(p, "detection_rate");
        if (!fa || !det) continue;
        xs.push_back(*fa);
        ys.push_back(*det);
        std::string tip = name + ": false alarms " + Pct(*fa) + ", detection " + Pct(*det);
        if (Num(p, "threshold")) tip += ", threshold " + FormatNumber(*Num(p, "threshold"));
        if (const std::string s = SettingText(Field(p, "setting")); !s.empty()) tip += "; " + s;
        tips.push_back(tip);
      }
    }
    const std::string color = FamilyColor(overall ? "overall" : name);
    const auto auc = Num(curve, "auc");
    const std::string label = (overall ? "overall frontier" : name) + (auc ? " (AUC " + Fixed(*auc, 3) + ")" : "");
    if (xs.size() > 1) {
      plot.Line("", xs, ys, svg::Stroke{color, overall ? 2.6 : 1.6, overall ? "" : "", 0.9});
    }
    plot.Points(label, xs, ys, {}, {}, color, overall ? svg::Marker::kCircle : svg::Marker::kSquare, tips,
                overall ? 3.2 : 2.8);
  };
  for (const auto& [name, curve] : roc->items()) {
    if (name != "overall") draw(name, curve, false);
  }
  if (const json* overall = Field(*roc, "overall")) draw("overall", *overall, true);
  // The operating and default points.
  for (const char* key : {"default_point", "operating_point"}) {
    const json* p = Field(*d.tuning, key);
    if (p == nullptr) continue;
    const Rate fa = TuningRate(Field(*p, "false_alarm_rate")), det = TuningRate(Field(*p, "detection_rate"));
    if (!fa.value || !det.value) continue;
    const bool op = std::string(key) == "operating_point";
    plot.Points(op ? "operating point" : "default thresholds", {*fa.value}, {*det.value}, {}, {},
                op ? "#000000" : "#888888", op ? svg::Marker::kDiamond : svg::Marker::kTriangle,
                {std::string(op ? "operating point" : "default thresholds") + ": false alarms " + Pct(*fa.value) +
                 ", detection " + Pct(*det.value)},
                6);
  }
  return o + "<div class=\"plots\">" + plot.Render() + "</div></section>";
}

std::string PodSection(const ReportData& d) {
  std::string o = "<section id=\"pod\"><h2>Detection probability against fault magnitude</h2>";
  if (!d.tuning) return o + TuneFirst(d.dir) + "</section>";
  const json* pod = Field(*d.tuning, "detection_probability");
  if (pod == nullptr || !pod->is_object() || pod->empty()) {
    return o + "<p>tuning.json has no detection-probability curves.</p></section>";
  }
  o += "<p>At the operating point. Points: measured detection rate per magnitude with its 95 % Wilson interval; "
       "line and band: fitted probability of detection with its 95 % confidence band; a90 and a90/95 marked "
       "where the fit reaches 90 %.</p><div class=\"plots\">";
  for (const auto& [family, f] : pod->items()) {
    const std::string key = Str(f, "magnitude_key");
    const std::string color = FamilyColor(family);
    svg::Plot plot("pod-" + IdPart(family), family, kHalfWidth, 330);
    plot.y().label = "detection probability";
    plot.y().min = 0;
    plot.y().max = 1;
    plot.x().label = (key.empty() ? std::string("magnitude") : key) + " (fault magnitude)";
    const json* pts = Field(f, "points");
    // Named magnitudes (a stuck sensor's lead) sit on a categorical axis, one slot per point.
    bool named = false;
    if (pts != nullptr && pts->is_array()) {
      for (const json& p : *pts) named = named || (Field(p, "magnitude") != nullptr && !p["magnitude"].is_number());
    }
    std::vector<std::string> categories;
    std::vector<double> xs, ys, lo, hi, mags, sevs;
    std::vector<std::string> tips;
    if (pts != nullptr && pts->is_array()) {
      for (const json& p : *pts) {
        const json* m = Field(p, "magnitude");
        const auto rate = Num(p, "rate");
        if (m == nullptr || !rate) continue;
        const std::string mtext = m->is_number()   ? FormatNumber(m->get<double>())
                                  : m->is_string() ? m->get<std::string>()
                                                   : m->dump();
        if (named) {
          xs.push_back(static_cast<double>(categories.size()));
          categories.push_back(mtext);
        } else {
          xs.push_back(m->get<double>());
          mags.push_back(xs.back());
          sevs.push_back(Num(p, "severity").value_or(std::nan("")));
        }
        ys.push_back(*rate);
        lo.push_back(Num(p, "low").value_or(*rate));
        hi.push_back(Num(p, "high").value_or(*rate));
        tips.push_back(key + " " + mtext + ": " + std::to_string(Count(p, "detected")) + " of " +
                       std::to_string(Count(p, "runs")) + " detected (" + Pct(*rate) + ", 95 % [" +
                       Fixed(100 * lo.back(), 1) + ", " + Fixed(100 * hi.back(), 1) + "] %)");
      }
    }
    if (named) {
      plot.x().categories = categories;
    } else {
      // Severity grows to the right: a falling parameter (kt_factor) gets a reversed axis.
      bool falling = false;
      for (size_t a = 0; a < mags.size(); ++a) {
        for (size_t b = 0; b < mags.size(); ++b) {
          if (mags[a] < mags[b] && sevs[a] > sevs[b]) falling = true;
        }
      }
      plot.x().reversed = falling;
      plot.set_caption(std::string("Severity grows to the right") + (falling ? " (smaller " + key + ")." : "."));
    }
    const json* fit = UsableFit(f);
    if (fit != nullptr && !named) {
      std::vector<double> cx, cp, cl, ch;
      if (const json* curve = Field(*fit, "curve"); curve != nullptr && curve->is_array()) {
        for (const json& c : *curve) {
          const auto m = Num(c, "magnitude"), p = Num(c, "pod");
          if (!m || !p) continue;
          cx.push_back(*m);
          cp.push_back(*p);
          cl.push_back(Num(c, "low").value_or(*p));
          ch.push_back(Num(c, "high").value_or(*p));
        }
      }
      if (!cx.empty()) {
        plot.Band("95 % confidence band", cx, cl, ch, color, 0.18);
        plot.Line("fitted detection probability", cx, cp, svg::Stroke{color, 2, "", 1});
      }
      plot.HLine(0.9, "90 %", svg::Stroke{"#666", 1, "4 3", 1});
      if (const json* a = Field(*fit, "a90"); a != nullptr && Num(*a, "magnitude")) {
        plot.VLine(*Num(*a, "magnitude"), "a90 = " + FormatNumber(*Num(*a, "magnitude")),
                   svg::Stroke{"#333", 1.4, "", 1});
      }
      if (const json* a = Field(*fit, "a90_95"); a != nullptr && Num(*a, "magnitude")) {
        plot.VLine(*Num(*a, "magnitude"), "a90/95 = " + FormatNumber(*Num(*a, "magnitude")),
                   svg::Stroke{"#b00020", 1.4, "5 3", 1});
      }
    }
    plot.Points("measured (Wilson 95 %)", xs, ys, lo, hi, color, svg::Marker::kCircle, tips);
    if (named) {
      plot.set_caption("Named magnitudes: no fitted curve.");
    } else if (fit == nullptr) {
      const json* made = Field(f, "fit");
      const std::string reason = made != nullptr ? Str(*made, "reason") : "";
      plot.set_caption("No fitted curve" + (reason.empty() ? std::string(".") : ": " + reason + "."));
    } else if (Field(*fit, "a90") == nullptr || Field(*fit, "a90_95") == nullptr) {
      plot.set_caption(std::string(Field(*fit, "a90") == nullptr ? "a90" : "a90/95") +
                       " not reached in the tested range (never extrapolated).");
    }
    o += plot.Render();
  }
  return o + "</div></section>";
}

std::string LatencyThresholdSection(const ReportData& d) {
  std::string o = "<section id=\"latency-threshold\"><h2>Latency against threshold</h2>";
  if (!d.tuning) return o + TuneFirst(d.dir) + "</section>";
  const json* lat = Field(*d.tuning, "latency");
  if (lat == nullptr || !lat->is_object() || lat->empty()) {
    return o + "<p>tuning.json has no latency curves.</p></section>";
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
  for (const auto& [family, f] : lat->items()) {
    const std::string param = Str(f, "parameter");
    svg::Plot plot("latency-threshold-" + IdPart(family), family, kHalfWidth, 320);
    plot.x().label = (param.empty() ? std::string("threshold") : param) + " (threshold)";
    plot.y().label = "latency after onset (s)";
    plot.y().include_zero = true;
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
    const std::string color = FamilyColor(family);
    plot.Line("95th percentile", xs, p95, svg::Stroke{color, 1.6, "5 3", 1}, svg::Marker::kTriangle);
    plot.Line("median", xs, med, svg::Stroke{color, 2.2, "", 1});
    plot.Points("", xs, med, {}, {}, color, svg::Marker::kCircle, tips, 3.5);
    if (setting != nullptr && Num(*setting, param)) {
      plot.VLine(*Num(*setting, param), "operating " + FormatNumber(*Num(*setting, param)),
                 svg::Stroke{"#000", 1.4, "", 1});
    }
    if (auto it = defaults.find(param); it != defaults.end()) {
      plot.VLine(it->second, "default " + FormatNumber(it->second), svg::Stroke{"#888", 1.4, "4 3", 1});
    }
    o += plot.Render();
  }
  return o + "</div></section>";
}

std::string ConfusionSection(const ReportData& d) {
  std::string o = "<section id=\"confusion\"><h2>Confusion matrix</h2>";
  const json* c = Field(d.summary, "confusion");
  const json* labels = c != nullptr ? Field(*c, "labels") : nullptr;
  const json* counts = c != nullptr ? Field(*c, "counts") : nullptr;
  if (labels == nullptr || counts == nullptr || !labels->is_array() || !counts->is_array()) {
    return o + "<p>summary.json has no confusion matrix.</p></section>";
  }
  svg::HeatMap h;
  h.id = "confusion";
  h.title = "True class against the class the monitor isolated";
  h.caption = "Counts of runs; shade: share of the row. healthy = no alarm, unknown = alarm without a family.";
  h.row_axis = "true class";
  h.col_axis = "isolated as";
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

std::string LatencyDistributionSection(const ReportData& d) {
  std::string o = "<section id=\"latency\"><h2>Latency distributions</h2>";
  if (d.latencies_s.empty() && d.misses.empty()) return o + "<p>No faulty runs in results.jsonl.</p></section>";
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
  if (d.table_5_3.empty()) return o + "<p>No thesis results.</p></section>";
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
    eff.set_caption(std::string("Judged windows; bar: the window's span; dashed: what a healthy joint would show for the "
                                "same motion.") + (s.first_alarm_s ? "" : " No alarm in this run."));
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
  // The same nominal model and the same signals as the run's own monitor: the same output.
  PowerEfficiencyMonitor monitor(campaign.monitor_model);
  double t_last = 0;
  const TickObserver observer = ObserveWith(&monitor, [&](const Tick& tick) {
    t_last = tick.t_s;
    s.t_s.push_back(tick.t_s);
    for (size_t k = 0; k < s.joints.size(); ++k) {
      const JointTick& jt = (*tick.joints)[s.joints[k] - 1];
      s.i_cmd_A[k].push_back(jt.i_cmd_A);
      s.i_supply_A[k].push_back(jt.i_supply_meas_A);
      s.tau_sensor_Nm[k].push_back(jt.tau_sensor_Nm);
    }
  });
  s.record = RunCase(campaign, spec, observer);
  monitor.Finish(t_last);
  s.monitor = monitor.output();
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
  d.tuning = options.tuning ? options.tuning(options.dir) : std::nullopt;

  // results.jsonl: latencies per family and the candidates for the plotted run.
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
      ++d.records;
      if (!first) first = r;
      if (!options.run_id.empty() && r.run_id == options.run_id) wanted = r;
      if (!r.ok || r.family.empty()) continue;
      if (r.detected) {
        if (r.latency_s && std::isfinite(*r.latency_s)) d.latencies_s[r.family].push_back(*r.latency_s);
        if (!first_detected) first_detected = r;
      } else {
        ++d.misses[r.family];
        if (!first_missed) first_missed = r;
      }
    }
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
  const fs::path campaign_path = dir / "campaign.json";
  Campaign campaign;
  try {
    const json file = ReadJsonFile(campaign_path.string());
    if (!file.is_object() || !file.contains("campaign")) {
      throw InputError(campaign_path.string(), "", "no \"campaign\" key: not written by `armfault run`");
    }
    // Relative file names (csv trajectories) resolve against DIR: the campaign's own folder is not recorded.
    campaign = CampaignFromJson(file["campaign"], campaign_path.string(), options.dir);
  } catch (const InputError& e) {
    if (!options.run_id.empty()) throw;
    s.error = e.what();
    return d;
  }
  if (s.run_id.empty()) {
    s.error = "results.jsonl holds no runs";
    return d;
  }
  const std::vector<CaseSpec> cases = ExpandCases(campaign);
  auto it = std::find_if(cases.begin(), cases.end(), [&](const CaseSpec& c) { return c.run_id == s.run_id; });
  if (it == cases.end()) {
    throw InputError("--run", "", "no run \"" + s.run_id + "\" in " + campaign_path.string() +
                                      " (run ids look like \"" + (cases.empty() ? "" : cases.front().run_id) + "\")");
  }
  const std::string why = s.why;
  s = SimulateRunSeries(campaign, *it);
  s.why = why;
  s.stored = chosen;
  return d;
}

std::string RenderReportHtml(const ReportData& d) {
  const json campaign = Field(d.summary, "campaign") ? d.summary["campaign"] : json::object();
  const std::string name = Str(campaign, "name");
  std::string o = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
                  "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">";
  o += "<title>armfault report: " + Escape(name) + "</title><style>" + kStyle + "</style></head><body><main>";
  o += "<h1>armfault report: " + Escape(name) + "</h1>";
  const bool met = Field(d.summary, "floors_met") && d.summary["floors_met"].is_boolean() &&
                   d.summary["floors_met"].get<bool>();
  o += "<p>Directory <code>" + Escape(d.dir) + "</code>, armfault " + Escape(Str(d.summary, "armfault_version")) +
       ". Floors: " + (met ? "<span class=\"met\">all met</span>" : "<span class=\"missed\">some MISSED</span>") +
       ". Hover over a point for its numbers.</p>";
  o += "<nav><a href=\"#summary\">rates and floors</a><a href=\"#operating-point\">operating point</a>"
       "<a href=\"#roc\">ROC</a><a href=\"#pod\">detection probability</a><a href=\"#latency-threshold\">latency vs "
       "threshold</a><a href=\"#confusion\">confusion</a><a href=\"#latency\">latency</a><a href=\"#thesis\">table "
       "5-3</a><a href=\"#run\">one run</a></nav>";
  o += SummarySection(d);
  o += OperatingPointSection(d);
  o += RocSection(d);
  o += PodSection(d);
  o += LatencyThresholdSection(d);
  o += ConfusionSection(d);
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
        " failed). Plots: report.html.\n\n";
  const json& latency = Field(overall, "latency") ? overall["latency"] : empty;
  md += MdTable({"metric", "rate [95 % Wilson interval] (successes/trials)"},
                {{"detection", RateText(SummaryRate(Field(overall, "detection")))},
                 {"false alarm", RateText(SummaryRate(Field(overall, "false_alarm")))},
                 {"isolation", RateText(SummaryRate(Field(overall, "isolation")))},
                 {"latency median / p95", SecondsText(Num(latency, "median_s")) + " / " + SecondsText(Num(latency, "p95_s"))}});

  md += "\n## Operating point\n\n";
  if (!d.tuning) {
    md += "No tuning results: run `armfault tune " + d.dir + "` first.\n";
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
    md += "\n## Smallest reliably detected fault (a90/95)\n\n";
    std::vector<std::vector<std::string>> rows;
    if (const json* pod = Field(t, "detection_probability"); pod != nullptr && pod->is_object()) {
      for (const auto& [family, f] : pod->items()) {
        rows.push_back({family, Str(f, "magnitude_key"), A90Text(f, "a90", false), A90Text(f, "a90_95", false)});
      }
    }
    md += rows.empty() ? "No detection-probability curves.\n" : MdTable({"family", "magnitude", "a90", "a90/95"}, rows);
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
