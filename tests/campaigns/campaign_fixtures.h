// Campaigns the campaign tests share.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace armfault::testing_support {

// 16 runs on mrr-config1's top joint: two fault entries (K_T on two joints and magnitudes, a
// friction grid with a uniform onset), 2 healthy runs, 2 repetitions, fleet variation, a floor.
inline nlohmann::json SmallCampaign(double duration_s) {
  nlohmann::json c = nlohmann::json::parse(R"({
    "name": "small", "seed": 3, "duration_s": 1.5,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [
      {"family": "kt_degradation", "joint": [2, 3], "kt_factor": [0.9, 0.6], "onset_s": 1.0},
      {"family": "friction_increase", "joint": 3, "friction_factor": {"from": 1.5, "to": 2.5, "steps": 3},
       "onset_s": {"uniform": [0.5, 1.5]}}
    ],
    "healthy": 2, "repetitions": 2,
    "variation": {"payload_kg": {"uniform": [0, 0.5]}, "friction_spread": 0.1},
    "floors": {"detection_rate": 0.5}
  })");
  c["duration_s"] = duration_s;
  return c;
}

}  // namespace armfault::testing_support
