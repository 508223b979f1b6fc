// The sections of the campaign report page (reports/campaign_report): each a function of the
// gathered ReportData that returns one <section id="..."> of HTML, plots inline. Which sections
// the page shows, in which order, is the table in campaign_report.cc. Internal to reports/.
#pragma once

#include <string>
#include <vector>

#include "reports/page/report_data.h"

namespace armfault::report {

// summary.json and results.jsonl (report_sections_results.cc).
std::string SummarySection(const ReportData& d);  // rates, floors, metric definitions
std::string ConfusionSection(const ReportData& d);
// The runs scored wrong with why, and the runs that could not be seen, as two tables.
std::string WhySection(const ReportData& d);
std::string LatencyDistributionSection(const ReportData& d);

// tuning.json (report_sections_tuning.cc); each says what to run when there is none.
std::string OperatingPointSection(const ReportData& d);
// tuning.json's "rate_calibration" (a sequential monitor's target rates beside the measured
// ones) as text cells, for the page and report.md; no rows without it.
std::vector<std::string> RateCalibrationHead();
std::vector<std::vector<std::string>> RateCalibrationRows(const nlohmann::json& tuning);
std::string RocSection(const ReportData& d);
std::string LatencyThresholdSection(const ReportData& d);

// Detection against fault magnitude (report_sections_pod.cc).
std::string PodSection(const ReportData& d);
// Only with DIR/boundary.json (`armfault boundary`): each cell's runs, fit and boundary.
std::string BoundarySection(const ReportData& d);
// One row per family: family, magnitude, a90 and a90/95 as run, and at the tuned operating
// point (tuning.json's fit); text cells, for the page and report.md.
std::vector<std::vector<std::string>> A90Rows(const ReportData& d);

// Simulated runs (report_sections_run.cc).
std::string ThesisSection(const ReportData& d);
std::string RunSection(const ReportData& d);  // every joint, the faulted one first
// The missed and misnamed faulty runs (ReportData::wrong_runs): one small efficiency plot each.
std::string WrongRunsSection(const ReportData& d);

// Only with --twin (ReportData::twin, report_sections_twin.cc): per joint each signal as
// recorded beside the twin's, their residual over time, and a table of the residuals' RMS.
std::string TwinSection(const ReportData& d);
// The table's head and rows (text, unescaped), and the sentence saying what was compared: for
// the page and report.md.
const std::vector<std::string>& TwinResidualHead();
std::vector<std::vector<std::string>> TwinResidualRows(const TwinComparison& c);
std::string TwinRunText(const TwinComparison& c);

}  // namespace armfault::report
