// What the report's sections share (reports/campaign_report): lenient access to the JSON
// files of an output directory, rates and numbers as text, HTML and Markdown tables, family
// colours, units of magnitudes and thresholds, and the plot widths. Internal to reports/.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <utility>
#include <vector>


namespace armfault::report {

using nlohmann::json;

// ---------------------------------------------------------------------------------------
// Lenient JSON access: the report shows what is there and says what is not, it does not
// validate (the writers of these files do).

// Escapes text for HTML text and attribute values (&, <, >, ", '); control characters other
// than tab and newlines become '?'.
std::string Escape(const std::string& text);
// x with `decimals` digits after the point ("%.*f", C locale); "-0.00" prints as "0.00"; NaN
// and infinities print as "nan" / "inf" / "-inf".
std::string Fixed(double x, int decimals);

// j[key] when j is an object holding a non-null key, else nullptr.
const json* Field(const json& j, const std::string& key);
// j[key] when it is a number / a string / a number (as long), else nullopt / "" / 0.
std::optional<double> Num(const json& j, const std::string& key);
std::string Str(const json& j, const std::string& key);
long Count(const json& j, const std::string& key);
// " 32 runs not excited (their fault could not act) are left out of every rate, as in
// summary.json." from tuning.json's "runs" (one denominator across commands); "" when none are
// (or the campaign scores them).
std::string TuningLeftOutText(const json& tuning);

// A rate with its 95 % Wilson interval, from summary.json ({rate, low, high, successes,
// trials}) or tuning.json ({value, low, high, count, runs}).
struct Rate {
  bool present = false;
  std::optional<double> value;
  double low = 0, high = 1;
  long k = 0, n = 0;
};
Rate SummaryRate(const json* j);
Rate TuningRate(const json* j);

// A fitted magnitude to 4 significant digits: the fit is not more precise than that.
std::string Sig4(double x);
// A fraction as a percentage: "12.5 %".
std::string Pct(double x, int decimals = 1);
// "12.5 % [8.1, 18.7] (20/160)"; "–" when absent, "no runs" without trials.
std::string RateText(const Rate& r);
// "0.123 s", "–" when absent.
std::string SecondsText(std::optional<double> s);
// Fixed colours per family, so a family looks the same in every plot.
std::string FamilyColor(const std::string& family);
// Ids in the page: family names are plain, but keep any text safe for an id.
std::string IdPart(const std::string& s);
// A setting {"kt_factor.worn": 0.95, ...} as "kt_factor.worn = 0.95, ...".
std::string SettingText(const json* setting);
// tuning.json's rule {"name": ..., parameters...} as "name (key = value, ...)".
std::string RuleText(const json* rule);
// A detection-probability fit that was made: present and not marked "ok": false.
const json* UsableFit(const json& family);

// ---------------------------------------------------------------------------------------
// HTML and Markdown tables. HTML cells are given already escaped (they may hold markup).

std::string HtmlTable(const std::vector<std::string>& head, const std::vector<std::vector<std::string>>& rows,
                      const std::string& cls = "");
// Text from the inputs (a campaign's or a trajectory's name, a path) as Markdown text: < > &
// as entities, so that no name carries raw HTML (a <script>) into a Markdown viewer; control
// characters as '?' (core/base/quote.h).
std::string MdText(const std::string& s);
std::string MdTable(const std::vector<std::string>& head, const std::vector<std::vector<std::string>>& rows);
// "met" / "MISSED", coloured.
std::string VerdictHtml(bool met);
// Text with `commands` in backticks as HTML: escaped, the commands in <code>.
std::string CodeSpans(const std::string& text);
// A fault magnitude or monitor threshold key with its unit, for axis labels
// ("kt_factor (× nominal K_T)"; docs/faults.md, docs/monitor.md); the key alone when unknown.
std::string WithUnit(const std::string& key);
// One sentence per metric, for the page, report.md and docs/campaign-format.md ("Metrics").
const std::vector<std::pair<std::string, std::string>>& MetricDefinitions();

// Keeps at most about `max_points` of a dense series (t, y) in (xs, ys), appended: each
// bucket's minimum and maximum in time order, so spikes survive the thinning.
void Thin(const std::vector<double>& t, const std::vector<double>& y, size_t max_points, std::vector<double>* xs,
          std::vector<double>* ys);

constexpr int kHalfWidth = 615;   // two plots side by side
constexpr int kFullWidth = 1250;  // one plot across the page

}  // namespace armfault::report
