#include "campaigns/spec/cases.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "core/base/rng.h"

namespace armfault {

namespace {

// Keys that time a fault rather than size it: not part of a scoring group.
const std::set<std::string> kTimingKeys = {"onset_s", "onset", "profile", "ramp_s", "duration_s", "period_s"};

uint64_t Fnv1a(const std::string& s) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : s) h = (h ^ c) * 0x100000001b3ULL;
  return h;
}

std::string ValueText(const nlohmann::json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number()) return FormatNumber(v.get<double>());
  if (v.is_object()) {
    // An onset condition: "<when>:<key>=<value>:..." in key order, without the ',' and '/'
    // that separate a run_id's parts.
    const auto when = v.find("when");
    std::string text = when != v.end() && when->is_string() ? when->get<std::string>() : "?";
    for (auto it = v.begin(); it != v.end(); ++it) {
      if (it.key() != "when") text += ":" + it.key() + "=" + ValueText(it.value());
    }
    return text;
  }
  return v.dump();
}



}  // namespace

nlohmann::json CaseSpec::VariationJson() const {
  nlohmann::json j = nlohmann::json::object();
  j["extra_payload_kg"] = extra_payload_kg;
  j["torque_noise_Nm"] = torque_noise_Nm < 0 ? nlohmann::json(nullptr) : nlohmann::json(torque_noise_Nm);
  j["friction_factors"] = friction_factors;
  // Only campaigns that use them carry the newer keys, so older results stay byte-identical.
  if (unit >= 0) j["unit"] = unit;
  if (ambient_C != 20) j["ambient_C"] = ambient_C;
  if (warm_start) j["start"] = "warm";
  if (!tolerance_draws.empty()) {
    nlohmann::json drawn = nlohmann::json::object();
    for (size_t k = 0; k < ToleranceKeys().size(); ++k) {
      nlohmann::json per_joint = nlohmann::json::array();
      for (const auto& joint : tolerance_draws) per_joint.push_back(joint[k]);
      drawn[ToleranceKeys()[k].name] = per_joint;
    }
    j["tolerances"] = drawn;
  }
  if (!confounder_draws.empty()) j["confounders"] = ConfounderDrawsToJson(confounder_draws);
  return j;
}

RobotConfig UnitRobot(const CampaignSpec& c, const CaseSpec& cs) {
  RobotConfig r = c.robot;
  for (size_t j = 0; j < r.modules.size(); ++j) {
    ModuleParams& m = r.modules[j];
    if (j < cs.confounder_draws.size()) {
      m.gearbox = cs.confounder_draws[j].gearbox;
      m.ripple = cs.confounder_draws[j].ripple;
    }
    const double f = j < cs.friction_factors.size() ? cs.friction_factors[j] : 1.0;
    m.friction.viscous_Nm_s_per_rad *= f;
    m.friction.coulomb_Nm *= f;
    m.friction.static_Nm *= f;
    if (j >= cs.tolerance_draws.size()) continue;
    const std::vector<double>& d = cs.tolerance_draws[j];  // ToleranceKeys() order
    m.motor.kt_Nm_per_A *= d[0];
    m.motor.phase_resistance_ohm *= d[1];
    m.inverter.switch_resistance_ohm *= d[2];
    m.inverter.switching_time_s *= d[3];
    m.inverter.quiescent_power_W *= d[4];
    m.drive.mesh_loss_fraction *= d[5];
    m.motor.rotor_inertia_kg_m2 *= d[6];
    m.friction.stribeck_s2_per_rad2 /= d[7] * d[7];  // F_t = 1 / v_s²: the Stribeck velocity scales by d
    m.torque_sensor.gain_error = d[8] - 1.0;
    m.torque_sensor.offset_error_Nm = d[9];
    m.inverter.supply_current_gain_error = d[10] - 1.0;
    m.inverter.supply_current_offset_error_A = d[11];
    m.inverter.bus_voltage_V *= d[12];
  }
  return r;
}

RobotConfig CaseRobot(const CampaignSpec& c, const CaseSpec& cs) {
  RobotConfig r = UnitRobot(c, cs);
  r.payload_kg += cs.extra_payload_kg;
  for (ModuleParams& m : r.modules) {
    if (cs.torque_noise_Nm >= 0) m.torque_sensor.noise_Nm = cs.torque_noise_Nm;
  }
  return r;
}

StatedTolerances StatedOf(const CampaignSpec& c) {
  StatedTolerances t = c.variation.tolerances;
  t.friction = c.variation.friction_spread;
  const Sweep& a = c.variation.ambient_C;
  t.ambient_min_C = a.uniform ? a.low : (a.values.empty() ? 20.0 : a.values[0].get<double>());
  t.ambient_max_C = a.uniform ? a.high : t.ambient_min_C;
  return t;
}

MonitorContext MonitorContextOf(const CampaignSpec& c) {
  MonitorContext context;
  context.robot = c.robot;
  context.has_tolerances = c.variation.has_tolerances;
  context.stated = StatedOf(c);
  context.commissioning = c.commissioning;
  context.input.source = c.source;
  context.input.base_dir = c.base_dir;
  return context;
}

namespace {

// Draws a run's variation from its own stream, after the uniform fault values.
void DrawVariation(const CampaignSpec& c, Rng* rng, CaseSpec* cs) {
  auto draw = [&](const Sweep& s, double fallback) {
    if (s.uniform) return s.low + (s.high - s.low) * rng->Uniform();
    if (!s.values.empty()) return s.values[0].get<double>();
    return fallback;
  };
  cs->extra_payload_kg = draw(c.variation.payload_kg, 0.0);
  cs->torque_noise_Nm = draw(c.variation.torque_noise_Nm, -1.0);
  cs->friction_factors.clear();
  for (size_t j = 0; j < c.robot.modules.size(); ++j) {
    const double u = rng->Uniform();
    cs->friction_factors.push_back(1.0 + c.variation.friction_spread * (2.0 * u - 1.0));
  }
  // Newer draws come after the older ones, and only where used, so older campaigns keep
  // their streams. A fleet's unit draws its friction and tolerances from its own stream.
  Rng unit_rng(0);
  Rng* parts = rng;
  if (c.variation.units > 0) {
    cs->unit = static_cast<int>(cs->seed % static_cast<unsigned long long>(c.variation.units));
    unit_rng = Rng(MixSeed(c.seed, 0x756e6974ULL + static_cast<uint64_t>(cs->unit)));
    parts = &unit_rng;
    for (size_t j = 0; j < c.robot.modules.size(); ++j) {
      cs->friction_factors[j] = 1.0 + c.variation.friction_spread * (2.0 * parts->Uniform() - 1.0);
    }
  }
  cs->tolerance_draws.clear();
  if (c.variation.has_tolerances) {
    for (size_t j = 0; j < c.robot.modules.size(); ++j) {
      std::vector<double> d;
      for (const ToleranceKey& k : ToleranceKeys()) {
        const double s = c.variation.tolerances.*k.member * (2.0 * parts->Uniform() - 1.0);
        d.push_back(k.absolute ? s : 1.0 + s);
      }
      cs->tolerance_draws.push_back(std::move(d));
    }
  }
  cs->ambient_C = draw(c.variation.ambient_C, 20.0);
  cs->warm_start = false;
  if (c.variation.warm_start_fraction >= 0) cs->warm_start = rng->Uniform() < c.variation.warm_start_fraction;
  // The unit's confounders from a stream of their own, so that no other draw moves.
  cs->confounder_draws.clear();
  if (c.variation.has_confounders) {
    Rng confounder_rng(c.variation.units > 0 ? MixSeed(c.seed, 0x636f6e66ULL + static_cast<uint64_t>(cs->unit))
                                             : MixSeed(cs->seed, 0x636f6e66ULL));
    cs->confounder_draws = DrawConfounders(c.variation.confounders, c.robot, &confounder_rng);
  }
}

// Runs of one fault entry: its value combinations x joints x repetitions.
long EntryRuns(const CampaignSpec& c, const FaultEntry& e) {
  if (e.compound) return c.repetitions;  // one case per trajectory x repetition
  long n = static_cast<long>(e.joints.size()) * c.repetitions;
  for (const auto& [key, sweep] : e.keys) n *= static_cast<long>(sweep.count());
  return n;
}

// A boundary search's run: its entry at the run's magnitude, the other keys at their one
// value or drawn from their uniform, the variation drawn after them, as for a grid case.
CaseSpec SearchCaseAt(const CampaignSpec& c, long index) {
  const SearchRun& run = c.search.runs[static_cast<size_t>(index)];
  const FaultEntry& e = c.faults[run.entry];
  const std::string& key = c.search.entries[run.entry].key;
  CaseSpec cs;
  cs.index = index;
  cs.trajectory = run.trajectory;
  cs.run_id = SearchRunId(c, run);
  cs.seed = MixSeed(c.seed, Fnv1a(cs.run_id));
  Rng rng(MixSeed(cs.seed, 0x7a71a710ULL));
  std::map<std::string, std::pair<nlohmann::json, std::string>> values;  // sorted: value, group text
  for (const auto& [name, sweep] : e.keys) {
    if (name == key) continue;
    if (sweep.uniform) {
      values[name] = {sweep.low + (sweep.high - sweep.low) * rng.Uniform(),
                      "U[" + FormatNumber(sweep.low) + "," + FormatNumber(sweep.high) + "]"};
    } else {
      values[name] = {sweep.values[0], ValueText(sweep.values[0])};
    }
  }
  values[key] = {run.magnitude, FormatNumber(run.magnitude)};
  nlohmann::json fault = {{"family", e.family}, {"joint", run.joint}};
  std::string group = e.family;
  for (const auto& [name, value] : values) {
    fault[name] = value.first;
    if (!kTimingKeys.count(name)) group += " " + name + "=" + value.second;
  }
  cs.group = group + " joint=" + std::to_string(run.joint);
  cs.fault = fault;
  DrawVariation(c, &rng, &cs);
  return cs;
}

}  // namespace

std::string SearchRunId(const CampaignSpec& c, const SearchRun& run) {
  const FaultEntry& e = c.faults[run.entry];
  return c.trajectories[run.trajectory].name + "/" + e.family + "#" + std::to_string(run.entry) + "/" +
         c.search.entries[run.entry].key + "=" + FormatNumber(run.magnitude) + "/j" + std::to_string(run.joint) + "/s" +
         std::to_string(run.number);
}

CaseSpec CaseAt(const CampaignSpec& c, long index) {
  const long total = CaseCount(c);
  if (index < 0 || index >= total) {
    throw std::out_of_range("case " + std::to_string(index) + " of a campaign of " + std::to_string(total) + " runs");
  }
  if (c.search.has_runs) return SearchCaseAt(c, index);
  long per_trajectory = c.healthy;
  for (const FaultEntry& e : c.faults) per_trajectory += EntryRuns(c, e);
  const size_t t = static_cast<size_t>(index / per_trajectory);
  long r = index % per_trajectory;
  const std::string& tname = c.trajectories[t].name;
  CaseSpec cs;
  cs.index = index;
  cs.trajectory = t;
  for (size_t ei = 0; ei < c.faults.size(); ++ei) {
    const FaultEntry& e = c.faults[ei];
    const long n = EntryRuns(c, e);
    if (r >= n) {
      r -= n;
      continue;
    }
    if (e.compound) {
      // One case per repetition: all its elements act together.
      cs.repetition = static_cast<int>(r);
      cs.run_id = tname + "/compound#" + std::to_string(ei) + "/" + e.name + "/r" + std::to_string(r);
      cs.group = "compound:" + e.name;
      cs.seed = MixSeed(c.seed, Fnv1a(cs.run_id));
      Rng rng(MixSeed(cs.seed, 0x7a71a710ULL));
      cs.fault = {{"family", "compound"}, {"name", e.name}, {"compound", e.elements}};
      DrawVariation(c, &rng, &cs);
      return cs;
    }
    // r = (values x joints + joint) x repetitions + repetition; values: last key fastest.
    const int rep = static_cast<int>(r % c.repetitions);
    r /= c.repetitions;
    const int joint = e.joints[static_cast<size_t>(r % static_cast<long>(e.joints.size()))];
    long combination = r / static_cast<long>(e.joints.size());
    std::vector<size_t> at(e.keys.size(), 0);
    for (size_t k = e.keys.size(); k-- > 0;) {
      const long count = static_cast<long>(e.keys[k].second.count());
      at[k] = static_cast<size_t>(combination % count);
      combination /= count;
    }
    cs.repetition = rep;
    std::string values, group = e.family;
    for (size_t k = 0; k < e.keys.size(); ++k) {
      const Sweep& s = e.keys[k].second;
      std::string text = s.uniform ? "U[" + FormatNumber(s.low) + "," + FormatNumber(s.high) + "]" : ValueText(s.values[at[k]]);
      if (s.uniform || s.values.size() > 1) values += (values.empty() ? "" : ",") + e.keys[k].first + "=" + text;
      if (!kTimingKeys.count(e.keys[k].first)) group += " " + e.keys[k].first + "=" + text;
    }
    group += " joint=" + std::to_string(joint);
    cs.run_id = tname + "/" + e.family + "#" + std::to_string(ei) + "/" + (values.empty() ? "-" : values) + "/j" +
                std::to_string(joint) + "/r" + std::to_string(rep);
    cs.group = group;
    cs.seed = MixSeed(c.seed, Fnv1a(cs.run_id));
    Rng rng(MixSeed(cs.seed, 0x7a71a710ULL));
    nlohmann::json fault = {{"family", e.family}, {"joint", joint}};
    for (size_t k = 0; k < e.keys.size(); ++k) {
      const Sweep& s = e.keys[k].second;
      fault[e.keys[k].first] = s.uniform ? nlohmann::json(s.low + (s.high - s.low) * rng.Uniform()) : s.values[at[k]];
    }
    cs.fault = fault;
    DrawVariation(c, &rng, &cs);
    return cs;
  }
  // The healthy runs, after every fault entry.
  cs.run_id = tname + "/healthy/" + std::to_string(r);
  cs.seed = MixSeed(c.seed, Fnv1a(cs.run_id));
  Rng rng(MixSeed(cs.seed, 0x7a71a710ULL));
  cs.fault = nullptr;
  DrawVariation(c, &rng, &cs);
  return cs;
}

std::vector<CaseSpec> ExpandCases(const CampaignSpec& c) {
  std::vector<CaseSpec> cases;
  const long n = CaseCount(c);
  cases.reserve(static_cast<size_t>(n));
  for (long k = 0; k < n; ++k) cases.push_back(CaseAt(c, k));
  return cases;
}

}  // namespace armfault
