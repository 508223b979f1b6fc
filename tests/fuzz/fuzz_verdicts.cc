// Fuzz target: a verdicts file's text, as `armfault score DIR VERDICTS.jsonl` reads it
// (campaigns/data/export.h ReadVerdicts: JSON Lines, each line a verdict checked against a
// three-joint, 4-s run), then every run's verdicts in time order scored as a live monitor's
// are (ScoreVerdicts, onset at 1 s). Every run_id but "unknown" is taken as a known run.
#include <algorithm>
#include <map>
#include <sstream>

#include "campaigns/data/export.h"
#include "core/monitors/monitor.h"
#include "faults/fault.h"
#include "tests/fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace armfault;
  static const std::vector<std::string> families = FaultFamilyNames();
  return fuzz::RejectCleanly([&] {
    std::istringstream in(fuzz::Text(data, size));
    std::map<std::string, MonitorOutput> runs;
    ReadVerdicts(
        in, fuzz::kSource, {3, 4.0, families},
        [](const std::string& run_id, std::string* hint) {
          if (run_id != "unknown") return std::string();
          if (hint) *hint = "did you mean \"known\"?";
          return std::string("unknown run_id");
        },
        [&](const std::string& run_id, const Verdict& v) { runs[run_id].verdicts.push_back(v); });
    for (auto& [run_id, output] : runs) {
      std::stable_sort(output.verdicts.begin(), output.verdicts.end(),
                       [](const Verdict& a, const Verdict& b) { return a.t_s < b.t_s; });
      ScoreVerdicts(output, 1.0, 1.0);
    }
  });
}
