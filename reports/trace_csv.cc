#include "reports/trace_csv.h"

#include <charconv>
#include <filesystem>
#include <string>

#include "core/base/output_file.h"

namespace armfault {

namespace {

// Per-joint columns: channel (name, unit, source) and accessor, one table so that header,
// channels.json and rows cannot disagree. Names as `armfault export` writes its signals.
struct Column {
  Channel channel;
  double (*get)(const JointTick&);
};

const std::vector<Column>& Columns() {
  static const std::vector<Column> columns = {
      {{"q_ref_rad", "rad", "sensor", "reference angle"}, [](const JointTick& j) { return j.signals.q_ref_rad; }},
      {{"q_rad", "rad", "truth", "joint angle"}, [](const JointTick& j) { return j.q_rad; }},
      {{"qd_rad_s", "rad/s", "truth", "joint velocity"}, [](const JointTick& j) { return j.qd_rad_s; }},
      {{"q_meas_rad", "rad", "sensor", "encoder angle, link side"}, [](const JointTick& j) { return j.signals.q_meas_rad; }},
      {{"qd_est_rad_s", "rad/s", "sensor", "controller's velocity estimate"},
       [](const JointTick& j) { return j.signals.qd_est_rad_s; }},
      {{"tau_sensor_Nm", "N m", "sensor", "torque-sensor reading after the 12-bit ADC"},
       [](const JointTick& j) { return j.signals.tau_sensor_Nm; }},
      {{"tau_true_Nm", "N m", "truth", "torque the harmonic drive transmits to the link"},
       [](const JointTick& j) { return j.tau_true_Nm; }},
      {{"i_cmd_A", "A", "sensor", "commanded current after the DAC (held for the next period)"},
       [](const JointTick& j) { return j.signals.i_cmd_A; }},
      {{"i_phase_a_A", "A", "truth", "phase a current at the row's time"}, [](const JointTick& j) { return j.i_phase_a_A; }},
      {{"i_peak_A", "A", "truth", "largest phase current during the period"},
       [](const JointTick& j) { return j.peak_phase_current_A; }},
      {{"i_supply_A", "A", "truth", "driver input current, mean over the period"},
       [](const JointTick& j) { return j.i_supply_A; }},
      {{"i_supply_meas_A", "A", "sensor", "the same with the supply-current sensor's noise"},
       [](const JointTick& j) { return j.signals.i_supply_meas_A; }},
      {{"v_bus_meas_V", "V", "sensor", "bus voltage"}, [](const JointTick& j) { return j.signals.v_bus_meas_V; }},
      {{"brake_engaged", "0/1", "truth", "brake engaged"}, [](const JointTick& j) { return j.brake_engaged ? 1.0 : 0.0; }},
      {{"driver_on", "0/1", "truth", "inverter switching (powered, not tripped)"},
       [](const JointTick& j) { return j.driver_enabled ? 1.0 : 0.0; }},
      {{"p_supply_W", "W", "truth", "power drawn from the bus (negative: regeneration)"},
       [](const JointTick& j) { return j.p_supply_W; }},
      {{"p_copper_W", "W", "truth", "winding (copper) loss"}, [](const JointTick& j) { return j.p_copper_W; }},
      {{"p_inverter_W", "W", "truth", "switch conduction, switching and diode losses"},
       [](const JointTick& j) { return j.p_inverter_W; }},
      {{"p_quiescent_W", "W", "truth", "driver, DSP and sensor electronics"}, [](const JointTick& j) { return j.p_quiescent_W; }},
      {{"p_magnetic_W", "W", "truth", "rate of change of the energy stored in the windings"},
       [](const JointTick& j) { return j.p_magnetic_W; }},
      {{"p_emf_W", "W", "truth", "electromagnetic power turned into rotor power"}, [](const JointTick& j) { return j.p_emf_W; }},
      {{"p_friction_W", "W", "truth", "motor friction + harmonic-drive mesh loss + brake, dissipated"},
       [](const JointTick& j) { return j.p_friction_W; }},
      {{"p_mech_out_W", "W", "truth", "power delivered to the link"}, [](const JointTick& j) { return j.p_mech_out_W; }},
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

std::vector<Channel> TraceCsvChannels(int joint_count) {
  std::vector<Channel> quantities;
  for (const Column& c : Columns()) quantities.push_back(c.channel);
  return ExpandPerJoint({{"t_s", "s", "sensor", "controller tick time"}}, quantities, joint_count);
}

std::vector<std::string> TraceCsvColumns(int joint_count) {
  std::vector<std::string> names;
  for (const Channel& c : TraceCsvChannels(joint_count)) names.push_back(c.Name());
  return names;
}

void WriteTraceChannels(const std::string& csv_path, int joint_count) {
  WriteAtomically(ChannelsSidecarPath(csv_path),
                  ChannelsJson(TraceCsvChannels(joint_count), std::filesystem::path(csv_path).filename().string()));
}

TraceCsvWriter::TraceCsvWriter(std::function<void(std::string_view)> sink, int joint_count) : sink_(std::move(sink)) {
  sink_(ChannelsCsvHeader(TraceCsvChannels(joint_count)));
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
