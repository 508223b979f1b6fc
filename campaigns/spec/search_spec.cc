#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "campaigns/spec/spec_parse.h"
#include "faults/fault.h"

namespace armfault {
namespace spec_parse {

namespace {

// The search's own "range": [low, high] for every entry, when given.
struct GivenRange {
  bool has = false;
  double low = 0, high = 0;
  std::string pointer;  // of "range" (where an entry's range ends come from when it is given)
};

// One fault entry's search: a family with a magnitude, one value for every other key (or a
// uniform), and a range of magnitudes (the search's, else the entry's own sweep) that are
// faults the family accepts, checked with `robot` when there is one. Throws the entry's errors.
SearchEntryRange EntryRange(const FaultEntry& e, const GivenRange& given, double tolerance, const RobotConfig* robot) {
  SearchEntryRange range;
  if (e.compound) {
    throw InputError("", e.pointer, "a compound fault entry cannot be searched (a boundary search sizes one fault "
                                    "by its magnitude); leave it out of a campaign with \"search\"");
  }
  range.key = FaultMagnitudeKey(e.family);
  if (range.key.empty()) {
    std::string sized;  // the families sized by a number, in the registry's order
    for (const std::string& family : FaultFamilyNames()) {
      if (!FaultMagnitudeKey(family).empty()) sized += (sized.empty() ? "" : ", ") + family;
    }
    throw InputError("", PointerJoin(e.pointer, "family"),
                     "\"" + e.family + "\" has no magnitude to search (the search needs a family sized by a number: " +
                         sized + "); leave this entry out of a campaign with \"search\"");
  }
  ErrorList entry_errors;
  const Sweep* magnitude = nullptr;
  for (const auto& [key, sweep] : e.keys) {
    if (key == range.key) {
      magnitude = &sweep;
      continue;
    }
    if (!sweep.uniform && sweep.values.size() > 1) {
      entry_errors.Add(InputError("", sweep.pointer, "a searched entry takes one value (or a uniform) for \"" + key +
                                                         "\": only its magnitude \"" + range.key + "\" is searched"));
    }
  }
  entry_errors.ThrowIfAny();
  std::string range_pointer = given.pointer;
  if (given.has) {
    range.low = given.low;
    range.high = given.high;
  } else if (!magnitude) {
    throw InputError("", e.pointer, "no \"" + range.key + "\" to search: give it as a list or a grid, or give "
                                    "\"range\": [low, high] in \"search\"");
  } else if (magnitude->uniform) {
    range.low = magnitude->low, range.high = magnitude->high;
    range_pointer = PointerJoin(magnitude->pointer, "uniform");
  } else {
    range_pointer = magnitude->pointer;
    range.low = range.high = magnitude->values[0].is_number() ? magnitude->values[0].get<double>() : 0;
    for (const nlohmann::json& x : magnitude->values) {
      if (!x.is_number()) throw InputError("", magnitude->pointer, "expected numbers to search, got " + Describe(x));
      range.low = std::min(range.low, x.get<double>());
      range.high = std::max(range.high, x.get<double>());
    }
    if (range.low == range.high) {
      throw InputError("", magnitude->pointer, "empty search range: \"" + range.key + "\" is the one value " +
                                                   FormatNumber(range.low) + "; give a list or grid of it, or "
                                                   "\"range\": [low, high] in \"search\"");
    }
  }
  // Both ends: a fault (severity > 0: the fit is in log severity) that the family accepts.
  for (int end = 0; end < 2; ++end) {
    const double m = end == 0 ? range.low : range.high;
    // Where the end comes from: the range's bound, the grid's end, the uniform's bound, or
    // the list element that holds it.
    std::string at;
    if (given.has || magnitude->uniform) {
      at = PointerJoin(range_pointer, std::to_string(end));
    } else if (magnitude->grid) {
      at = PointerJoin(range_pointer, end == 0 ? "from" : "to");
    } else {
      size_t index = 0;
      while (index + 1 < magnitude->values.size() && magnitude->values[index].get<double>() != m) ++index;
      at = PointerJoin(range_pointer, index);
    }
    entry_errors.Try([&] {
      if (!(FaultSeverity(range.key, m) > 0) || !std::isfinite(FaultSeverity(range.key, m))) {
        throw InputError("", at, e.family + ": " + range.key + " " + FormatNumber(m) +
                                     " is no fault (severity 0): a search range must exclude the healthy value");
      }
      if (robot == nullptr) return;
      nlohmann::json spec = {{"family", e.family}, {"joint", e.joints[0]}, {range.key, m}};
      for (const auto& [key, sweep] : e.keys) {
        if (key != range.key) spec[key] = sweep.uniform ? nlohmann::json(sweep.low) : sweep.values[0];
      }
      try {
        MakeFault(spec, e.pointer, *robot);
      } catch (const InputError& err) {
        throw InputError("", at, err.message());
      }
    });
  }
  entry_errors.ThrowIfAny();
  range.tolerance = tolerance > 0 ? tolerance : (range.high - range.low) / 10;
  range.lattice = std::pow(10.0, std::floor(std::log10(range.high - range.low)) - 3);
  return range;
}

// The "runs" list (written by `armfault boundary`): the runs made so far, in case order.
void ParseSearchRuns(const nlohmann::json* runs, const std::string& rp, CampaignSpec* c, ErrorList* errors) {
  SearchSpec& s = c->search;
  errors->Try([&] {
    if (!runs->is_array()) throw InputError("", rp, "expected an array of runs, got " + Describe(*runs));
    std::map<std::tuple<size_t, size_t, int>, long> numbers;
    for (size_t k = 0; k < runs->size(); ++k) {
      const std::string p = PointerJoin(rp, k);
      ObjectReader run(( *runs)[k], p);
      run.AllowOnly({"trajectory", "entry", "joint", "magnitude"});
      SearchRun r;
      const std::string name = run.RequireString("trajectory");
      const auto t = std::find_if(c->trajectories.begin(), c->trajectories.end(),
                                  [&](const CampaignTrajectory& x) { return x.name == name; });
      if (t == c->trajectories.end()) throw InputError("", run.PointerTo("trajectory"), "no trajectory \"" + name + "\"");
      r.trajectory = static_cast<size_t>(t - c->trajectories.begin());
      const int entry = run.RequireInt("entry");
      RequireInRange(entry, 0, static_cast<double>(c->faults.size()) - 1, run.PointerTo("entry"));
      r.entry = static_cast<size_t>(entry);
      r.joint = run.RequireInt("joint");
      const std::vector<int>& joints = c->faults[r.entry].joints;
      if (std::find(joints.begin(), joints.end(), r.joint) == joints.end()) {
        throw InputError("", run.PointerTo("joint"), "joint " + std::to_string(r.joint) + " is not a joint of fault entry " +
                                                         std::to_string(entry));
      }
      r.magnitude = run.RequireNumber("magnitude");
      r.number = numbers[{r.trajectory, r.entry, r.joint}]++;
      s.runs.push_back(r);
    }
    s.has_runs = true;
  });
}

}  // namespace

void ParseSearch(const nlohmann::json& v, const std::string& pointer, CampaignSpec* c, bool faults_ok, bool robot_ok,
                 ErrorList* errors) {
  ObjectReader reader(v, pointer);
  errors->Try([&] { reader.AllowOnly({"target", "confidence", "range", "batch", "max_runs", "tolerance", "runs"}); });
  SearchSpec& s = c->search;
  s.present = true;
  errors->Try([&] {
    reader.OptionalNumber("target", &s.target);
    RequireInRange(s.target, 0.5, 0.999, reader.PointerTo("target"));
  });
  errors->Try([&] {
    reader.OptionalNumber("confidence", &s.confidence);
    RequireInRange(s.confidence, 0.5, 0.9999, reader.PointerTo("confidence"));
  });
  errors->Try([&] {
    reader.OptionalInt("batch", &s.batch);
    RequireInRange(s.batch, 2, 1000, reader.PointerTo("batch"));
  });
  errors->Try([&] {
    reader.OptionalInt("max_runs", &s.max_runs);
    RequireInRange(s.max_runs, 2, 100000, reader.PointerTo("max_runs"));
  });
  bool has_range = false;
  double range_low = 0, range_high = 0;
  const bool range_ok = errors->Try([&] {
    if (const auto* r = reader.Find("range")) {
      const std::string rp = reader.PointerTo("range");
      if (!r->is_array() || r->size() != 2) throw InputError("", rp, "expected [low, high] magnitudes, got " + Describe(*r));
      ErrorList both;
      both.Try([&] { range_low = AsNumber((*r)[0], PointerJoin(rp, 0)); });
      both.Try([&] { range_high = AsNumber((*r)[1], PointerJoin(rp, 1)); });
      both.ThrowIfAny();
      if (range_low > range_high) {
        throw InputError("", PointerJoin(rp, 0), "inverted search range: low " + FormatNumber(range_low) +
                                                     " is greater than high " + FormatNumber(range_high));
      }
      if (range_low == range_high) {
        throw InputError("", rp, "empty search range [" + FormatNumber(range_low) + ", " + FormatNumber(range_high) +
                                     "]: give low < high");
      }
      has_range = true;
    }
  });
  double tolerance = 0;
  errors->Try([&] {
    if (reader.Has("tolerance")) {
      reader.OptionalNumber("tolerance", &tolerance);
      RequireAbove(tolerance, 0, reader.PointerTo("tolerance"));
    }
  });
  if (!faults_ok || !range_ok) return;
  if (c->faults.empty()) {
    errors->Add(InputError("", pointer, "a search needs fault entries to search: \"faults\" is empty"));
    return;
  }
  // Each fault entry: a family with a magnitude, one value for every other key (or a
  // uniform), and a range of magnitudes that are faults the family accepts.
  const GivenRange given{has_range, range_low, range_high, reader.PointerTo("range")};
  bool entries_ok = true;
  for (size_t i = 0; i < c->faults.size(); ++i) {
    SearchEntryRange range;
    entries_ok &= errors->Try([&] { range = EntryRange(c->faults[i], given, tolerance, robot_ok ? &c->robot : nullptr); });
    s.entries.push_back(range);
  }
  if (!entries_ok) return;
  if (const auto* runs = reader.Find("runs")) ParseSearchRuns(runs, reader.PointerTo("runs"), c, errors);
}

}  // namespace spec_parse

double SearchLatticeValue(const SearchEntryRange& range, double magnitude) {
  const double m = std::min(range.high, std::max(range.low, magnitude));
  // Through the decimal text, so a value prints and reads back as the same short number.
  return std::stod(FormatNumber(std::round(m / range.lattice) * range.lattice));
}

}  // namespace armfault
