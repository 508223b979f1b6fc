// Detection probability against fault magnitude (PoD): a logistic hit/miss fit in log severity
// (faults/fault.h, FaultSeverity) with its 95 % band, a90 and a90/95 as in MIL-HDBK-1823A, for
// tuning.json (campaigns/tuning/tuning.h), the boundary search (campaigns/tuning/boundary.h) and the report.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace armfault {

// A hit/miss fit of detection probability against severity (> 0): logistic in log severity,
// maximum likelihood with Firth's bias reduction (defined under complete separation).
struct PodFit {
  bool ok = false;
  std::string reason;  // why not, when !ok
  double intercept = 0, slope = 0;
  double cov[2][2] = {{0, 0}, {0, 0}};
  double Probability(double severity) const;
  // The one-sided 95 % (z = 1.645) or two-sided band (z = 1.96) at a severity.
  double Bound(double severity, double z) const;
};
PodFit FitPod(const std::vector<double>& severity, const std::vector<bool>& detected);

// The named magnitude of a fault without a numeric one (a stuck sensor's "lead", a short's
// "kind"); "" if none.
std::string PodCategory(const nlohmann::json& fault);
// The "fit" object of a detection-probability entry (docs/tuning.md): FitPod of the runs'
// outcomes against severity, its curve with the two-sided 95 % band over the tested range,
// a90 and a90_95 (never extrapolated), or {"ok": false, "reason"}.
nlohmann::json PodFitJson(const std::string& magnitude_key, const std::vector<double>& severities,
                          const std::vector<bool>& hits);

}  // namespace armfault
