#include "campaigns/data/channels.h"

#include <filesystem>

#include <nlohmann/json.hpp>

namespace armfault {

std::vector<Channel> ExpandPerJoint(const std::vector<Channel>& leading, const std::vector<Channel>& quantities,
                                    int joints) {
  std::vector<Channel> out = leading;
  for (int j = 1; j <= joints; ++j) {
    for (Channel c : quantities) {
      c.joint = j;
      out.push_back(std::move(c));
    }
  }
  return out;
}

std::string ChannelsCsvHeader(const std::vector<Channel>& channels) {
  std::string header;
  for (const Channel& c : channels) header += (header.empty() ? "" : ",") + c.Name();
  return header + "\n";
}

std::string ChannelsJson(const std::vector<Channel>& channels, const std::string& file) {
  nlohmann::json list = nlohmann::json::array();
  for (const Channel& c : channels) {
    list.push_back({{"name", c.Name()},
                    {"quantity", c.quantity},
                    {"unit", c.unit},
                    {"source", c.source},
                    {"joint", c.joint ? nlohmann::json(c.joint) : nlohmann::json(nullptr)},
                    {"description", c.description}});
  }
  return nlohmann::json{{"file", file}, {"channels", list}}.dump(2) + "\n";
}

std::string ChannelsSidecarPath(const std::string& csv_path) {
  std::filesystem::path p(csv_path);
  std::string stem = p.filename().string();
  if (stem.size() > 4 && stem.compare(stem.size() - 4, 4, ".csv") == 0) stem.resize(stem.size() - 4);
  return (p.parent_path() / (stem + ".channels.json")).string();
}

std::vector<Channel> MonitorSignalChannels(int joints) {
  static const std::vector<Channel> quantities = {
      {"q_ref_rad", "rad", "sensor", "reference angle the controller tracks"},
      {"qd_ref_rad_s", "rad/s", "sensor", "reference velocity"},
      {"q_meas_rad", "rad", "sensor", "encoder angle, link side"},
      {"qd_est_rad_s", "rad/s", "sensor", "controller's velocity estimate"},
      {"tau_sensor_Nm", "N m", "sensor", "torque-sensor reading after the ADC"},
      {"i_cmd_A", "A", "sensor", "commanded current after the DAC"},
      {"i_supply_meas_A", "A", "sensor", "driver input current, mean over the control period, with the sensor's noise"},
      {"v_bus_meas_V", "V", "sensor", "bus voltage"},
      {"winding_temp_C", "°C", "sensor", "winding temperature sensor; empty (NaN) where the robot declares none"},
  };
  return ExpandPerJoint({{"t_s", "s", "sensor", "controller tick time"}}, quantities, joints);
}

}  // namespace armfault
