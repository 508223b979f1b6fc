// armfault's command line as a function: parses argv (argv[0] is the program's name), runs the
// chosen subcommand and returns the process's exit status (0 ok, 2 bad input, 3 a failed run,
// 1 floors not met ...; README.md). Messages go to stdout and stderr. Called once per process:
// by the `armfault` binary's main, and by `python3 -m armfault` (python/armfault/__main__.py),
// where the Python package has installed its builder of Python monitors (SetMonitorHost).
#pragma once

namespace armfault {

int CliMain(int argc, char** argv);

}  // namespace armfault
