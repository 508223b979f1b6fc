#include "campaigns/scoring/run_record.h"

#include <stdexcept>

#include "core/base/json_input.h"

namespace armfault {

namespace {

nlohmann::json OptTime(const std::optional<double>& x) {
  return x ? nlohmann::json(RoundToMicroseconds(*x)) : nlohmann::json(nullptr);
}
nlohmann::json Opt(const std::optional<double>& x) { return x ? nlohmann::json(*x) : nlohmann::json(nullptr); }
nlohmann::json StrOrNull(const std::string& s) { return s.empty() ? nlohmann::json(nullptr) : nlohmann::json(s); }

const nlohmann::json& Get(const nlohmann::json& j, const char* key) {
  auto it = j.find(key);
  if (it == j.end()) throw std::runtime_error(std::string("missing key \"") + key + "\"");
  return *it;
}
template <class T>
T As(const nlohmann::json& j, const char* key) {
  try {
    return Get(j, key).get<T>();
  } catch (const nlohmann::json::exception&) {
    throw std::runtime_error(std::string("key \"") + key + "\" has the wrong type");
  }
}
std::string StrOrEmpty(const nlohmann::json& j, const char* key) {
  const nlohmann::json& v = Get(j, key);
  return v.is_null() ? std::string() : As<std::string>(j, key);
}
std::optional<double> OptDouble(const nlohmann::json& j, const char* key) {
  const nlohmann::json& v = Get(j, key);
  if (v.is_null()) return std::nullopt;
  return As<double>(j, key);
}

}  // namespace

nlohmann::json ToJson(const RunRecord& r) {
  nlohmann::json j;
  j["case"] = r.case_index;
  j["run_id"] = r.run_id;
  j["trajectory"] = r.trajectory;
  j["fault"] = r.fault;
  j["family"] = StrOrNull(r.family);
  j["joint"] = r.joint == 0 ? nlohmann::json(nullptr) : nlohmann::json(r.joint);
  j["onset_s"] = r.family.empty() || !r.injected() ? nlohmann::json(nullptr) : nlohmann::json(RoundToMicroseconds(r.onset_s));
  j["magnitude_key"] = StrOrNull(r.magnitude_key);
  j["magnitude"] = r.magnitude_key.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.magnitude);
  j["group"] = r.group;
  j["seed"] = r.seed;
  j["engine"] = r.engine;
  j["repetition"] = r.repetition;
  j["variation"] = r.variation;
  j["status"] = r.ok ? "ok" : "failed";
  j["reason"] = StrOrNull(r.failure_reason);
  j["effect"] = r.effect;
  j["excited"] = r.family.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.excited());
  j["not_excited_reason"] = StrOrNull(r.not_excited_reason);
  j["detected"] = r.detected;
  j["detection_time_s"] = OptTime(r.detection_time_s);
  j["latency_s"] = OptTime(r.latency_s);
  j["isolated_family"] = StrOrNull(r.isolated_family);
  j["isolated_joint"] = r.isolated_joint == 0 ? nlohmann::json(nullptr) : nlohmann::json(r.isolated_joint);
  j["magnitude_name"] = StrOrNull(r.magnitude_name);
  j["magnitude_estimate"] = Opt(r.magnitude_estimate);
  j["confidence"] = r.confidence;
  j["alarm_before_onset"] = r.alarm_before_onset;
  j["miss_reason"] = StrOrNull(r.miss_reason);
  if (r.conditional_onset) {
    j["onset_fired_s"] = OptTime(r.onset_fired_s);
    j["not_injected_reason"] = StrOrNull(r.not_injected_reason);
  }
  if (r.is_compound()) j["compound"] = r.compound;
  if (r.unlabelled) j["label"] = "unlabelled";
  if (!r.sensor_saturated_s.empty()) {
    nlohmann::json sat = nlohmann::json::object();
    for (const auto& [joint, seconds] : r.sensor_saturated_s) sat[std::to_string(joint)] = seconds;
    j["sensor_saturated_s"] = sat;
  }
  return j;
}

RunRecord RunRecordFromJson(const nlohmann::json& j) {
  if (!j.is_object()) throw std::runtime_error("not a JSON object");
  RunRecord r;
  r.case_index = As<long>(j, "case");
  r.run_id = As<std::string>(j, "run_id");
  r.trajectory = As<std::string>(j, "trajectory");
  r.fault = Get(j, "fault");
  r.family = StrOrEmpty(j, "family");
  r.joint = Get(j, "joint").is_null() ? 0 : As<int>(j, "joint");
  r.onset_s = OptDouble(j, "onset_s").value_or(0.0);
  r.magnitude_key = StrOrEmpty(j, "magnitude_key");
  r.magnitude = OptDouble(j, "magnitude").value_or(0.0);
  r.group = As<std::string>(j, "group");
  r.seed = As<unsigned long long>(j, "seed");
  // Optional: records written before there was a second engine were all ODE's.
  if (const auto it = j.find("engine"); it != j.end()) r.engine = As<std::string>(j, "engine");
  r.repetition = As<int>(j, "repetition");
  r.variation = Get(j, "variation");
  const std::string status = As<std::string>(j, "status");
  if (status != "ok" && status != "failed") throw std::runtime_error("key \"status\" is neither \"ok\" nor \"failed\"");
  r.ok = status == "ok";
  r.failure_reason = StrOrEmpty(j, "reason");
  r.effect = Get(j, "effect");
  // Optional: records written before observability was scored count as excited.
  if (const auto it = j.find("not_excited_reason"); it != j.end() && !it->is_null()) {
    r.not_excited_reason = As<std::string>(j, "not_excited_reason");
  }
  r.detected = As<bool>(j, "detected");
  r.detection_time_s = OptDouble(j, "detection_time_s");
  r.latency_s = OptDouble(j, "latency_s");
  r.isolated_family = StrOrEmpty(j, "isolated_family");
  r.isolated_joint = Get(j, "isolated_joint").is_null() ? 0 : As<int>(j, "isolated_joint");
  r.magnitude_name = StrOrEmpty(j, "magnitude_name");
  r.magnitude_estimate = OptDouble(j, "magnitude_estimate");
  r.confidence = As<double>(j, "confidence");
  r.alarm_before_onset = As<bool>(j, "alarm_before_onset");
  if (const auto it = j.find("miss_reason"); it != j.end() && !it->is_null()) r.miss_reason = As<std::string>(j, "miss_reason");
  // Only for a conditional onset.
  if (const auto it = j.find("onset_fired_s"); it != j.end()) {
    r.conditional_onset = true;
    r.onset_fired_s = OptDouble(j, "onset_fired_s");
    r.not_injected_reason = StrOrEmpty(j, "not_injected_reason");
  }
  if (const auto it = j.find("sensor_saturated_s"); it != j.end()) {
    if (!it->is_object()) throw std::runtime_error("key \"sensor_saturated_s\" has the wrong type");
    for (const auto& [joint, seconds] : it->items()) {
      if (!seconds.is_number()) throw std::runtime_error("key \"sensor_saturated_s\" has the wrong type");
      r.sensor_saturated_s[std::stoi(joint)] = seconds.get<double>();
    }
  }
  if (const auto it = j.find("compound"); it != j.end() && !it->is_null()) {
    if (!it->is_array()) throw std::runtime_error("key \"compound\" has the wrong type");
    r.compound = *it;
  }
  if (const auto it = j.find("label"); it != j.end()) {
    if (*it != "unlabelled") throw std::runtime_error("key \"label\" is not \"unlabelled\"");
    r.unlabelled = true;
  }
  // Written inline by older versions; now in decisions.jsonl.
  if (const auto it = j.find("decision"); it != j.end()) r.decision = *it;
  return r;
}

bool IsolatedRight(const RunRecord& r) {
  if (!r.detected) return false;
  if (!r.is_compound()) return r.isolated_family == r.family && r.isolated_joint == r.joint;
  for (const nlohmann::json& e : r.compound) {
    if (e.value("family", "") == r.isolated_family && e.value("joint", 0) == r.isolated_joint) return true;
  }
  return false;
}

nlohmann::json DecisionLineJson(const RunRecord& r) {
  return {{"case_index", r.case_index}, {"run_id", r.run_id}, {"decision", r.decision}};
}

std::string MonitorCostLine(const RunRecord& r) {
  nlohmann::json j = {{"case", r.case_index}, {"run_id", r.run_id}};
  if (r.cost.is_object()) {
    j.update(r.cost);
  } else {
    j["ticks"] = 0;
  }
  return j.dump() + "\n";
}

DecisionLine DecisionLineFromJson(const nlohmann::json& j) {
  if (!j.is_object()) throw std::runtime_error("not a JSON object");
  DecisionLine d;
  d.case_index = As<long>(j, "case_index");
  d.run_id = As<std::string>(j, "run_id");
  d.decision = Get(j, "decision");
  if (!d.decision.is_null() && !d.decision.is_object()) throw std::runtime_error("key \"decision\" has the wrong type");
  return d;
}

}  // namespace armfault
