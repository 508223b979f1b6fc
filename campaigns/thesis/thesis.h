// The thesis experiments (chapter 5) on the simulated arm, evaluated by the power-efficiency
// monitor exactly as the thesis evaluates them (eq 5-5 over the forward-flow windows of the
// top joint). See docs/monitor.md, "Thesis experiments", for the mapping of each experiment.
//   Exp. 1: K_T factor n = 1 ... 0.5 on the top joint, sine_pair 25 deg (table 5-3).
//   Exp. 2: top and second joints together, cosine ramp 25 deg; n = 1 and 0.5.
//   Exp. 3: top joint, sine_pair 3 deg; without and with a spring load on the motor shaft.
#pragma once

#include <string>
#include <vector>

namespace armfault {

struct ThesisRow {
  std::string label;       // "n = 0.9", "spring load"
  double factor = 1;       // K_T factor (exp. 1, 2); 0 / 1 for without / with load (exp. 3)
  double thesis_pct = 0;   // published efficiency [%]
  double armfault_pct = 0; // eq 5-5 efficiency of the simulated run [%]
  double thesis_ratio = 1, armfault_ratio = 1;  // relative to the experiment's first row
  int windows = 0;         // forward-flow windows that went into the figure
  bool ok = true;          // the run completed
  std::string failure;
};

struct ThesisExperiment {
  std::string id;           // "exp1", "exp2", "exp3"
  std::string title;
  std::string motion;       // the reference motion, as run
  std::string fault;        // the fault varied, as run
  std::vector<ThesisRow> rows;
};

struct ThesisResults {
  std::vector<ThesisExperiment> experiments;
  unsigned long long seed = 1;
};

// Runs all thesis experiments (in parallel with oneTBB; results do not depend on threads).
ThesisResults RunThesisExperiments(unsigned long long seed);

}  // namespace armfault
