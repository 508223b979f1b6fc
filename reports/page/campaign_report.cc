#include "reports/page/campaign_report.h"

#include <filesystem>

#include "campaigns/running/runner.h"
#include "reports/page/report_common.h"
#include "reports/page/report_sections.h"
#include "reports/page/report_js.h"
#include "reports/page/vega_plot.h"

namespace armfault {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using report::A90Rows;
using report::BoundarySection;
using report::ConfusionSection;
using report::Count;
using report::Escape;
using report::Field;
using report::Fixed;
using report::LatencyDistributionSection;
using report::LatencyThresholdSection;
using report::MdTable;
using report::MdText;
using report::MetricDefinitions;
using report::Num;
using report::OperatingPointSection;
using report::PodSection;
using report::RateText;
using report::RocSection;
using report::RuleText;
using report::RunSection;
using report::SecondsText;
using report::SettingText;
using report::Sig4;
using report::Str;
using report::SummaryRate;
using report::SummarySection;
using report::ThesisSection;
using report::TuningRate;
using report::TwinResidualHead;
using report::TwinResidualRows;
using report::TwinRunText;
using report::TwinSection;
using report::WhySection;
using report::WrongRunsSection;

// One section of the page: its id (the <section id> its function writes, and the link's
// target), the link text in the page's nav, and when it is shown (nullptr: always). A new
// section is a function in report_sections.h and one row here.
struct ReportSection {
  const char* id;
  const char* link;
  std::string (*html)(const ReportData&);
  bool (*shown)(const ReportData&) = nullptr;
};

bool HasBoundary(const ReportData& d) { return d.boundary.has_value(); }
bool HasTwin(const ReportData& d) { return d.twin.has_value(); }

// The page's sections, in page order.
const ReportSection kSections[] = {
    {"summary", "rates and floors", SummarySection},
    {"operating-point", "operating point", OperatingPointSection},
    {"roc", "ROC", RocSection},
    {"pod", "detection probability", PodSection},
    {"boundary", "boundary", BoundarySection, HasBoundary},
    {"latency-threshold", "latency vs threshold", LatencyThresholdSection},
    {"confusion", "confusion", ConfusionSection},
    {"why", "why wrong", WhySection},
    {"wrong-runs", "missed runs", WrongRunsSection},
    {"latency", "latency", LatencyDistributionSection},
    {"thesis", "table 5-3", ThesisSection},
    {"run", "one run", RunSection},
    {"twin", "twin vs recorded", TwinSection, HasTwin},
};

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
.plot{background:#fff;border:1px solid #eee;max-width:100%;overflow:hidden}
#copy-status{display:none;position:fixed;bottom:14px;left:50%;transform:translateX(-50%);background:#222;color:#fff;padding:6px 12px;border-radius:4px;font-size:13px;z-index:10}
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

std::string RenderReportHtml(const ReportData& d) {
  const json campaign = Field(d.summary, "campaign") ? d.summary["campaign"] : json::object();
  const std::string name = Str(campaign, "name");
  std::string o = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
                  "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">";
  // The campaign's content hash, also for machines reading the page.
  if (!d.campaign_hash.empty()) o += "<meta name=\"armfault-campaign-hash\" content=\"" + Escape(d.campaign_hash) + "\">";
  o += "<title>armfault report: " + Escape(name) + "</title><style>" + kStyle + "</style></head>";
  // The campaign file of the trace command a click on a run copies (vega_plot.h).
  o += "<body data-campaign=\"" + Escape((fs::path(d.dir) / "campaign.json").string()) + "\"><main>";
  o += "<h1>armfault report: " + Escape(name) + "</h1>";
  const bool met = Field(d.summary, "floors_met") && d.summary["floors_met"].is_boolean() &&
                   d.summary["floors_met"].get<bool>();
  o += "<p>Directory <code>" + Escape(d.dir) + "</code>, armfault " + Escape(Str(d.summary, "armfault_version")) +
       ". Floors: " + (met ? "<span class=\"met\">all met</span>" : "<span class=\"missed\">some MISSED</span>") +
       ". Hover over a point for its numbers and its run; drag or scroll in a plot to zoom (double click: back); "
       "click a run's mark to copy its <code>armfault trace</code> command.</p>"
       "<noscript><p class=\"missing\">The plots need JavaScript (inlined in this page; nothing is fetched).</p></noscript>";
  o += "<p>" + CampaignHashText(d, true) + "</p>";
  o += "<nav>";
  // Links to the sections every page has, in page order, then to those shown only with their
  // input, so that a page without them reads as before they existed.
  for (bool optional : {false, true}) {
    for (const ReportSection& s : kSections) {
      if ((s.shown != nullptr) == optional && (s.shown == nullptr || s.shown(d))) {
        o += "<a href=\"#" + std::string(s.id) + "\">" + s.link + "</a>";
      }
    }
  }
  o += "</nav>";
  for (const ReportSection& s : kSections) {
    if (s.shown == nullptr || s.shown(d)) o += s.html(d);
  }
  // The plotting libraries, inlined (nothing fetched), then the script that draws every plot.
  o += "<p class=\"note\">Plots: " + std::string(report_js::Versions()) + ", inlined.</p></main>";
  o += "<div id=\"copy-status\" role=\"status\"></div>";
  o += std::string("<script>") + report_js::Vega() + "</script><script>" + report_js::VegaLite() + "</script><script>" +
       report_js::VegaEmbed() + "</script><script>" + vega::ReportPlotScript() + "</script>";
  o += "</body></html>\n";
  return o;
}

std::string RenderReportMarkdown(const ReportData& d) {
  const json empty = json::object();
  const json& s = d.summary;
  const json& campaign = Field(s, "campaign") ? s["campaign"] : empty;
  const json& overall = Field(s, "overall") ? s["overall"] : empty;
  const json& runs = Field(s, "runs") ? s["runs"] : empty;
  std::string md = "# armfault report: " + MdText(Str(campaign, "name")) + "\n\n";
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
    md += "No tuning results: " + MdText(d.tuning_source) + ".\n";
  } else {
    const json& t = *d.tuning;
    const json& op = Field(t, "operating_point") ? t["operating_point"] : empty;
    md += "Rule: " + RuleText(Field(t, "rule")) + ". Setting: " + SettingText(Field(op, "setting")) + "." +
          MdText(report::TuningLeftOutText(t)) + "\n\n";
    md += MdTable({"metric", "operating point"},
                  {{"detection", RateText(TuningRate(Field(op, "detection_rate")))},
                   {"false alarm", RateText(TuningRate(Field(op, "false_alarm_rate")))},
                   {"isolation", RateText(TuningRate(Field(op, "isolation_accuracy")))},
                   {"latency median / p95",
                    SecondsText(Num(op, "latency_median_s")) + " / " + SecondsText(Num(op, "latency_p95_s"))}});
    if (const auto rows = report::RateCalibrationRows(t); !rows.empty()) {
      std::vector<std::vector<std::string>> md_rows = rows;
      for (auto& row : md_rows) {
        for (std::string& cell : row) cell = MdText(cell);
      }
      md += "\nFalse alarms per healthy hour, set for and measured (the sequential decision):\n\n" +
            MdTable(report::RateCalibrationHead(), md_rows);
    }
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
  if (d.twin) {
    md += "\n## Twin against the recording\n\n" + MdText(TwinRunText(*d.twin)) + "\n\n";
    std::vector<std::vector<std::string>> rows = TwinResidualRows(*d.twin);
    for (auto& row : rows) {
      for (auto& cell : row) cell = MdText(cell);
    }
    md += MdTable(TwinResidualHead(), rows);
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
