// ODE 0.16 thread safety. InitOde() once in the process before threads start (idempotent);
// EnsureOdeThreadData() on every thread before it touches ODE (cheap after the first call;
// TBB workers are arbitrary threads). Every world also gets its own threading
// implementation (see simulation.cc): the shared default crashes with two worlds stepping
// at once.
#pragma once

namespace armfault {

void InitOde();
void EnsureOdeThreadData();

}  // namespace armfault
