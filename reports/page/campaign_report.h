// The campaign report (`armfault report DIR`): DIR/report.html, a self-contained page (Vega-Lite
// plots of reports/vega_plot drawn by the inlined vega-embed, inline CSS, nothing fetched) and
// DIR/report.md, a short Markdown summary. Inputs, all in DIR:
//   summary.json   rates with Wilson intervals, per-family rates, confusion matrix, floors
//   results.jsonl  latency distributions per family; which run to re-simulate
//   campaign.json  the campaign, to re-simulate one run with RunCase
//   tuning.json    ROC, the tuned detection-probability fit, latency against threshold,
//                  operating point (`armfault tune DIR`; optional: without it the tuner runs
//                  with its defaults, and if that fails those sections say why and what to
//                  run; format: docs/tuning.md)
//   boundary.json  each cell's detection boundary (`armfault boundary`; optional: a section of
//                  its own, absent without it)
//   thesis.json    table 5-3 (`armfault thesis -o DIR`; optional: else the thesis experiments
//                  are run with seed ReportOptions::thesis_seed)
// Units in the page: rates as fractions or %, times in s, currents in A, torques in N m,
// magnitudes and thresholds in their own (docs/faults.md, docs/monitor.md).
//
// Code: the data is gathered in report_data.{h,cc}, the page's sections are report_sections.h (one
// row each in the table of campaign_report.cc), their shared helpers report_common.h.
//
// Provenance: the files must be of one campaign (campaigns/scoring/provenance.h). The report refuses
// (InputError, exit status 2) a summary.json or tuning.json whose campaign_hash is not
// campaign.json's (or summary.json's, without campaign.json), a tuning.json without one, and a
// results.jsonl line that is not a case of campaign.json. The page shows the hash.
#pragma once

#include <string>

#include "reports/page/report_data.h"

namespace armfault {

std::string RenderReportHtml(const ReportData& data);
std::string RenderReportMarkdown(const ReportData& data);

struct ReportPaths {
  std::string html, markdown;
};
// Gathers, renders and writes both files.
ReportPaths WriteCampaignReport(const ReportOptions& options);

}  // namespace armfault
