// The armfault subcommands. Each returns the process exit status:
// 0 success, 1 a floor missed, 2 invalid input or usage, 3 some runs failed.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace armfault {

struct TraceOptions {
  std::string run_file;                 // empty: thesis experiment 1
  std::string robot;                    // overrides the file's robot (preset name)
  std::optional<double> duration_s;     // overrides the file's duration
  std::optional<long long> seed;        // overrides the file's seed
  std::vector<std::string> joint_specs; // "J=<trajectory JSON>"
  std::vector<std::string> fault_specs; // fault JSON objects, added to the file's "faults"
  std::string output = "trace.csv";
  std::string monitor_output;           // monitor verdicts and windows as JSON (optional)
  bool quiet = false;
};
int RunTrace(const TraceOptions& options);

}  // namespace armfault
