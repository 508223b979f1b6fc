#include "reports/page/report_common.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>

#include "core/base/quote.h"
#include "faults/fault.h"

namespace armfault::report {

std::string MdText(const std::string& s) { return EscapeMarkup(s, MarkupQuotes::kKeep); }

std::string Escape(const std::string& text) { return EscapeMarkup(text, MarkupQuotes::kHtml); }

std::string Fixed(double x, int decimals) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", std::clamp(decimals, 0, 17), x);
  std::string s = buf;
  // "-0.00" is zero: print it without the sign so equal values print equally.
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

namespace {

// A Markdown table cell: '|' escaped, line breaks as spaces.
std::string MdCell(const std::string& s) {
  std::string out;
  for (char c : MdText(s)) out += c == '|' ? std::string("\\|") : c == '\n' ? std::string(" ") : std::string(1, c);
  return out;
}

// The unit of a fault magnitude or a monitor threshold ("kt_factor", "kt_factor.worn"), for
// axis labels (docs/faults.md, docs/monitor.md); "" when unknown.
std::string UnitOf(std::string key) {
  const std::string worn = ".worn";
  if (key.size() > worn.size() && key.compare(key.size() - worn.size(), worn.size(), worn) == 0) {
    key.resize(key.size() - worn.size());
  }
  // A fault family's magnitude: its registry row (faults/registry.cc).
  if (const std::string unit = FaultMagnitudeUnit(key); !unit.empty()) return unit;
  static const std::map<std::string, std::string> units = {
      {"sensor_drift_Nm", "N m"},
      {"significance", "standard errors"},
      {"lead", "named"},
      {"kind", "named"}};
  auto it = units.find(key);
  return it == units.end() ? "" : it->second;
}

}  // namespace

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

std::string TuningLeftOutText(const json& tuning) {
  const json* runs = Field(tuning, "runs");
  if (runs == nullptr) return "";
  const json* included = Field(*runs, "not_excited_included");
  const long not_excited = included != nullptr && included->is_boolean() && included->get<bool>() ? 0 : Count(*runs, "not_excited");
  const long not_injected = Count(*runs, "not_injected");
  std::string text;
  if (not_excited > 0) text += " " + std::to_string(not_excited) + " runs not excited (their fault could not act)";
  if (not_injected > 0) {
    text += std::string(text.empty() ? " " : " and ") + std::to_string(not_injected) + " runs not injected";
  }
  std::string out = text.empty() ? "" : text + " are left out of every rate, as in summary.json.";
  if (const long compound = Count(*runs, "compound"); compound > 0) {
    out += " " + std::to_string(compound) + " compound runs are left out too (tuning scores single faults; summary.json scores them).";
  }
  return out;
}

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

std::string Sig4(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", x);
  return buf;
}

std::string Pct(double x, int decimals) { return Fixed(100 * x, decimals) + " %"; }

std::string RateText(const Rate& r) {
  if (!r.present) return "–";
  if (!r.value) return "no runs";
  return Pct(*r.value) + " [" + Fixed(100 * r.low, 1) + ", " + Fixed(100 * r.high, 1) + "] (" + std::to_string(r.k) +
         "/" + std::to_string(r.n) + ")";
}

std::string SecondsText(std::optional<double> s) { return s ? Fixed(*s, 3) + " s" : "–"; }

std::string FamilyColor(const std::string& family) {
  // A fault family's is in its registry row (faults/registry.cc).
  if (const std::string color = FaultFamilyColor(family); !color.empty()) return color;
  static const std::map<std::string, std::string> colors = {{"overall", "#222222"}, {"healthy", "#7f7f7f"}};
  auto it = colors.find(family);
  if (it != colors.end()) return it->second;
  static const char* const spare[] = {"#bcbd22", "#17becf", "#7f7f7f", "#393b79", "#637939"};
  size_t h = 0;
  for (char c : family) h = h * 31 + static_cast<unsigned char>(c);
  return spare[h % 5];
}

std::string IdPart(const std::string& s) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) || c == '_' ? c : '-';
  return out;
}

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

const json* UsableFit(const json& family) {
  const json* fit = Field(family, "fit");
  if (fit == nullptr || !fit->is_object()) return nullptr;
  const json* ok = Field(*fit, "ok");
  return ok != nullptr && ok->is_boolean() && !ok->get<bool>() ? nullptr : fit;
}

// ---------------------------------------------------------------------------------------
// HTML and Markdown tables. HTML cells are given already escaped (they may hold markup).

std::string HtmlTable(const std::vector<std::string>& head, const std::vector<std::vector<std::string>>& rows,
                      const std::string& cls) {
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

std::string WithUnit(const std::string& key) {
  const std::string unit = UnitOf(key);
  return unit.empty() ? key : key + " (" + unit + ")";
}

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

}  // namespace armfault::report
