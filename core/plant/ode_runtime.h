// ODE 0.16 thread safety and error handling. InitOde() once in the process before threads
// start (idempotent); EnsureOdeThreadData() on every thread before it touches ODE (cheap after
// the first call; TBB workers are arbitrary threads). Every world also gets its own threading
// implementation (see simulation.cc): the shared default crashes with two worlds stepping
// at once.
//
// ODE's errors as a last resort (the robot's checks, core/plant/robot/mass_properties.h, are meant to
// keep ODE from ever asserting): InitOde() installs ODE's error, debug and message handlers.
// ODE calls the debug handler for a failed internal assertion and aborts if it returns, and the
// error handler for a usage error and exits if it returns; both handlers therefore throw
// OdeError on the calling thread, which unwinds out of ODE (Debian's libode8 is C++ built with
// exceptions and unwind tables: its landing pads run ODE's own cleanups). The run that met it
// catches it (Simulate, simulation.cc), destroys its world and threading implementation and
// calls RenewOdeThreadData(), so the thread's next run is the same as on a fresh thread
// (tests/core/plant/ode_runtime_test.cc). A message (dMessage: a warning, ODE goes on) is
// printed as ODE prints it and kept as the thread's last, so an error right after it (the
// "inertia must be positive definite" before dMassCheck's assertion) carries it.
#pragma once

#include <stdexcept>
#include <string>

namespace armfault {

// An error ODE reported on this thread: "ODE internal error 1: assertion ... failed in ...".
class OdeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

void InitOde();
// Allocates this thread's ODE data once; forgets the thread's last ODE message (a new world).
void EnsureOdeThreadData();
// After an OdeError, once the failed run's world is destroyed: frees this thread's ODE data and
// allocates it afresh.
void RenewOdeThreadData();

}  // namespace armfault
