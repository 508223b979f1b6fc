#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/base/output_file.h"
#include "app/commands/commands.h"
#include "campaigns/thesis/thesis.h"
#include "core/base/json_input.h"
#include "reports/thesis_report.h"

namespace armfault {

namespace {

void WriteFile(const std::filesystem::path& path, const std::string& text) { WriteAtomically(path, text); }

}  // namespace

ThesisTrend CheckThesisTrend(const ThesisResults& results) {
  ThesisTrend t;
  const ThesisExperiment& e = results.experiments.at(0);
  for (size_t k = 0; k < e.rows.size(); ++k) {
    const ThesisRow& r = e.rows[k];
    if (!std::isfinite(r.armfault_pct) || (k > 0 && !(r.armfault_pct < e.rows[k - 1].armfault_pct))) t.monotonic = false;
    const double d = std::fabs(r.armfault_ratio - r.thesis_ratio);
    if (!(d <= t.max_ratio_deviation)) t.max_ratio_deviation = std::isfinite(d) ? d : INFINITY;
  }
  for (size_t x = 1; x < results.experiments.size(); ++x) {
    const ThesisExperiment& ex = results.experiments[x];
    if (!(ex.rows.back().armfault_pct < ex.rows.front().armfault_pct)) t.same_direction = false;
  }
  return t;
}

int RunThesis(const ThesisOptions& o) {
  const ThesisResults results = RunThesisExperiments(o.seed);
  std::filesystem::create_directories(o.output_dir);
  const std::filesystem::path dir(o.output_dir);
  WriteFile(dir / "thesis.json", ThesisToJson(results).dump(2) + "\n");
  WriteFile(dir / "thesis.md", ThesisToMarkdown(results));

  for (const ThesisExperiment& e : results.experiments) {
    std::printf("%s\n  motion: %s\n  fault:  %s\n", e.title.c_str(), e.motion.c_str(), e.fault.c_str());
    std::printf("  %-12s %10s %12s %12s %14s %8s\n", "case", "thesis_%", "armfault_%", "thesis_ratio",
                "armfault_ratio", "windows");
    for (const ThesisRow& r : e.rows) {
      std::printf("  %-12s %10.2f %12.2f %12.3f %14.3f %8d%s\n", r.label.c_str(), r.thesis_pct, r.armfault_pct,
                  r.thesis_ratio, r.armfault_ratio, r.windows, r.ok ? "" : ("  FAILED: " + r.failure).c_str());
    }
  }
  const ThesisTrend t = CheckThesisTrend(results);
  std::printf("trend: table 5-3 falls monotonically: %s; largest |armfault ratio - thesis ratio| = %.3f (limit %.2f); "
              "experiments 2 and 3 drop in the same direction: %s\n",
              t.monotonic ? "yes" : "NO", t.max_ratio_deviation, ThesisTrend::kRatioLimit,
              t.same_direction ? "yes" : "NO");
  std::printf("wrote %s and %s\n", (dir / "thesis.json").string().c_str(), (dir / "thesis.md").string().c_str());
  return t.holds() ? 0 : 1;
}

}  // namespace armfault
