#include "reports/thesis_report.h"

#include <cmath>
#include <cstdio>

namespace armfault {

namespace {

// Rounded for reading; the JSON keeps 2 decimals of a percentage and 3 of a ratio.
double Round(double x, double scale) { return std::isfinite(x) ? std::round(x * scale) / scale : x; }

nlohmann::json Number(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

nlohmann::json Rows(const ThesisExperiment& e, const char* factor_key, bool boolean_factor) {
  nlohmann::json rows = nlohmann::json::array();
  for (const ThesisRow& r : e.rows) {
    nlohmann::json j;
    j[factor_key] = boolean_factor ? nlohmann::json(r.factor != 0) : nlohmann::json(r.factor);
    j["thesis_pct"] = r.thesis_pct;
    j["armfault_pct"] = Number(Round(r.armfault_pct, 100));
    j["thesis_ratio"] = Number(Round(r.thesis_ratio, 1000));
    j["armfault_ratio"] = Number(Round(r.armfault_ratio, 1000));
    j["windows"] = r.windows;
    if (!r.ok) j["failure"] = r.failure;
    rows.push_back(j);
  }
  return rows;
}

}  // namespace

nlohmann::json ThesisToJson(const ThesisResults& results) {
  nlohmann::json j;
  j["armfault_version"] = ARMFAULT_VERSION;
  j["seed"] = results.seed;
  j["efficiency"] = "eq 5-5 over the top joint's forward-flow windows (docs/monitor.md)";
  j["experiments"] = nlohmann::json::array();
  for (const ThesisExperiment& e : results.experiments) {
    j["experiments"].push_back({{"id", e.id}, {"title", e.title}, {"motion", e.motion}, {"fault", e.fault}});
  }
  j["table_5_3"] = Rows(results.experiments.at(0), "kt_factor", false);
  j["experiment_2"] = Rows(results.experiments.at(1), "kt_factor", false);
  j["experiment_3"] = Rows(results.experiments.at(2), "spring_load", true);
  return j;
}

std::string ThesisToMarkdown(const ThesisResults& results) {
  std::string md = "# Thesis experiments on the simulated arm\n\n";
  md += "Efficiency: eq 5-5 over the top joint's forward-flow windows (docs/monitor.md). Seed " +
        std::to_string(results.seed) + ".\n";
  char line[256];
  for (const ThesisExperiment& e : results.experiments) {
    md += "\n## " + e.title + "\n\nMotion: " + e.motion + ". Fault: " + e.fault + ".\n\n";
    md += "| case | thesis η (%) | armfault η (%) | thesis ratio | armfault ratio | windows |\n";
    md += "|---|---:|---:|---:|---:|---:|\n";
    for (const ThesisRow& r : e.rows) {
      std::snprintf(line, sizeof line, "| %s | %.2f | %.2f | %.3f | %.3f | %d |\n", r.label.c_str(), r.thesis_pct,
                    r.armfault_pct, r.thesis_ratio, r.armfault_ratio, r.windows);
      md += line;
    }
  }
  return md;
}

}  // namespace armfault
