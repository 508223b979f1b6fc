#include "campaigns/running/results_csv.h"

#include <cstdio>
#include <optional>

#include "core/base/csv.h"
#include "faults/fault.h"

namespace armfault {

namespace {

std::string Quote(const std::string& s) { return CsvText(s); }

std::string Number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  return buf;
}
std::string Number(const std::optional<double>& x) { return x ? Number(*x) : std::string(); }

}  // namespace

std::string MagnitudeUnit(const std::string& magnitude_key) {
  const std::string label = FaultMagnitudeUnit(magnitude_key);
  // "× nominal K_T", "× brake holding torque": a ratio, dimensionless.
  return label.rfind("×", 0) == 0 ? "1" : label;
}

namespace {

}  // namespace

std::string ResultsCsvHeader() {
  return "case,run_id,trajectory,group,family,joint,onset_s,magnitude_key,magnitude,seed,repetition,unit,ambient_C,"
         "status,reason,took_effect,detected,alarm_before_onset,detection_time_s,latency_s,isolated_family,"
         "isolated_joint,isolated,magnitude_name,magnitude_estimate,confidence,magnitude_unit,miss_reason\n";
}

std::string ResultsCsvRow(const RunRecord& r) {
  const bool faulty = !r.family.empty();
  const nlohmann::json& v = r.variation;
  const std::string unit = v.is_object() && v.contains("unit") ? std::to_string(v["unit"].get<int>()) : "";
  const std::string ambient = v.is_object() && v.contains("ambient_C") ? Number(v["ambient_C"].get<double>()) : "";
  std::string took;
  if (r.effect.is_object() && r.effect.contains("took_effect") && r.effect["took_effect"].is_boolean()) {
    took = r.effect["took_effect"].get<bool>() ? "true" : "false";
  } else if (r.is_compound() && r.effect.is_array()) {
    // A compound fault took effect when one of its elements did.
    bool any = false, known = false;
    for (const nlohmann::json& e : r.effect) {
      if (e.is_object() && e.contains("took_effect") && e["took_effect"].is_boolean()) {
        known = true;
        any = any || e["took_effect"].get<bool>();
      }
    }
    if (known) took = any ? "true" : "false";
  }
  const bool isolated = faulty && IsolatedRight(r);
  std::string row;
  auto add = [&](const std::string& cell) { row += (row.empty() ? "" : ",") + cell; };
  row = std::to_string(r.case_index);
  add(Quote(r.run_id));
  add(Quote(r.trajectory));
  add(Quote(r.group));
  add(Quote(r.family));
  add(faulty && !r.is_compound() ? std::to_string(r.joint) : "");
  add(faulty ? Number(r.onset_s) : "");
  add(Quote(r.magnitude_key));
  add(r.magnitude_key.empty() ? "" : Number(r.magnitude));
  add(std::to_string(r.seed));
  add(std::to_string(r.repetition));
  add(unit);
  add(ambient);
  add(r.ok ? "ok" : "failed");
  add(Quote(r.failure_reason));
  add(took);
  add(r.detected ? "true" : "false");
  add(r.alarm_before_onset ? "true" : "false");
  add(Number(r.detection_time_s));
  add(Number(r.latency_s));
  add(Quote(r.isolated_family));
  add(r.isolated_joint ? std::to_string(r.isolated_joint) : "");
  add(faulty ? (isolated ? "true" : "false") : "");
  add(Quote(r.magnitude_name));
  add(Number(r.magnitude_estimate));
  add(r.detected ? Number(r.confidence) : "");
  add(r.magnitude_key.empty() ? "" : Quote(MagnitudeUnit(r.magnitude_key)));
  add(Quote(r.miss_reason));
  return row + "\n";
}

}  // namespace armfault
