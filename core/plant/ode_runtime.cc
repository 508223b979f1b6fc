#include "core/plant/ode_runtime.h"

#include <ode/ode.h>

#include <mutex>

namespace armfault {

namespace {
struct ThreadData {
  bool allocated = false;
  ~ThreadData() {
    if (allocated) dCleanupODEAllDataForThread();
  }
};
thread_local ThreadData thread_data;
}  // namespace

void InitOde() {
  static std::once_flag once;
  std::call_once(once, [] { dInitODE2(0); });
}

void EnsureOdeThreadData() {
  if (thread_data.allocated) return;
  InitOde();
  dAllocateODEDataForThread(dAllocateMaskAll);
  thread_data.allocated = true;
}

}  // namespace armfault
