#include "reports/trace_csv.h"

#include <charconv>
#include <string>

namespace armfault {

namespace {

// Per-joint columns: name and accessor, one table so header and rows cannot disagree.
struct Column {
  const char* name;
  double (*get)(const JointTick&);
};

const std::vector<Column>& Columns() {
  static const std::vector<Column> columns = {
      {"q_ref", [](const JointTick& j) { return j.signals.q_ref_rad; }},
      {"q", [](const JointTick& j) { return j.q_rad; }},
      {"qd", [](const JointTick& j) { return j.qd_rad_s; }},
      {"q_meas", [](const JointTick& j) { return j.signals.q_meas_rad; }},
      {"qd_est", [](const JointTick& j) { return j.signals.qd_est_rad_s; }},
      {"tau_sensor", [](const JointTick& j) { return j.signals.tau_sensor_Nm; }},
      {"tau_true", [](const JointTick& j) { return j.tau_true_Nm; }},
      {"i_cmd", [](const JointTick& j) { return j.signals.i_cmd_A; }},
      {"i_phase_a", [](const JointTick& j) { return j.i_phase_a_A; }},
      {"i_peak", [](const JointTick& j) { return j.peak_phase_current_A; }},
      {"i_supply", [](const JointTick& j) { return j.i_supply_A; }},
      {"i_supply_meas", [](const JointTick& j) { return j.signals.i_supply_meas_A; }},
      {"v_bus", [](const JointTick& j) { return j.signals.v_bus_meas_V; }},
      {"brake", [](const JointTick& j) { return j.brake_engaged ? 1.0 : 0.0; }},
      {"driver_on", [](const JointTick& j) { return j.driver_enabled ? 1.0 : 0.0; }},
      {"p_supply", [](const JointTick& j) { return j.p_supply_W; }},
      {"p_copper", [](const JointTick& j) { return j.p_copper_W; }},
      {"p_inverter", [](const JointTick& j) { return j.p_inverter_W; }},
      {"p_quiescent", [](const JointTick& j) { return j.p_quiescent_W; }},
      {"p_magnetic", [](const JointTick& j) { return j.p_magnetic_W; }},
      {"p_emf", [](const JointTick& j) { return j.p_emf_W; }},
      {"p_friction", [](const JointTick& j) { return j.p_friction_W; }},
      {"p_mech_out", [](const JointTick& j) { return j.p_mech_out_W; }},
  };
  return columns;
}

// Shortest text that reads back to the same double: traces are exact and diffable.
void AppendNumber(std::string* line, double x) {
  char buffer[32];
  auto result = std::to_chars(buffer, buffer + sizeof(buffer), x);
  line->append(buffer, result.ptr);
}

}  // namespace

std::vector<std::string> TraceCsvColumns(int joint_count) {
  std::vector<std::string> names = {"t"};
  for (int j = 1; j <= joint_count; ++j) {
    for (const Column& c : Columns()) names.push_back(std::string(c.name) + "_" + std::to_string(j));
  }
  return names;
}

TraceCsvWriter::TraceCsvWriter(std::function<void(std::string_view)> sink, int joint_count) : sink_(std::move(sink)) {
  std::string header;
  for (const std::string& name : TraceCsvColumns(joint_count)) header += (header.empty() ? "" : ",") + name;
  sink_(header + '\n');
}

TraceCsvWriter::TraceCsvWriter(std::ostream* out, int joint_count)
    : TraceCsvWriter([out](std::string_view text) { out->write(text.data(), static_cast<std::streamsize>(text.size())); },
                     joint_count) {}

void TraceCsvWriter::Write(const Tick& tick) {
  std::string line;
  line.reserve(64 * 16);
  AppendNumber(&line, tick.t_s);
  for (const JointTick& joint : *tick.joints) {
    for (const Column& c : Columns()) {
      line += ',';
      AppendNumber(&line, c.get(joint));
    }
  }
  line += '\n';
  sink_(line);
}

}  // namespace armfault
