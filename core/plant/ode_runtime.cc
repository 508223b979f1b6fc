#include "core/plant/ode_runtime.h"

#include <ode/ode.h>

#include <cstdarg>
#include <cstdio>
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
// The last message ODE printed on this thread in the current world ("" if none).
thread_local std::string last_message;

std::string FormatOde(const char* format, va_list ap) {
  char text[1024];
  va_list copy;
  va_copy(copy, ap);
  std::vsnprintf(text, sizeof text, format, copy);
  va_end(copy);
  return text;
}

[[noreturn]] void ThrowOdeError(const char* kind, int num, const char* format, va_list ap) {
  std::string text = std::string(kind) + " " + std::to_string(num) + ": " + FormatOde(format, ap);
  if (!last_message.empty()) text += " (after ODE message: " + last_message + ")";
  last_message.clear();
  throw OdeError(text);
}

// ODE would exit(1) after this one returns.
void OnOdeError(int num, const char* format, va_list ap) { ThrowOdeError("ODE error", num, format, ap); }
// ODE would abort() after this one returns.
void OnOdeDebug(int num, const char* format, va_list ap) { ThrowOdeError("ODE internal error", num, format, ap); }
// A warning; printed exactly as ODE's own printMessage does.
void OnOdeMessage(int num, const char* format, va_list ap) {
  last_message = FormatOde(format, ap);
  std::fflush(stderr);
  std::fflush(stdout);
  if (num) std::fprintf(stderr, "\nODE Message %d: %s\n", num, last_message.c_str());
  else std::fprintf(stderr, "\nODE Message: %s\n", last_message.c_str());
  std::fflush(stderr);
}

}  // namespace

void InitOde() {
  static std::once_flag once;
  std::call_once(once, [] {
    dSetErrorHandler(&OnOdeError);
    dSetDebugHandler(&OnOdeDebug);
    dSetMessageHandler(&OnOdeMessage);
    dInitODE2(0);
  });
}

void EnsureOdeThreadData() {
  last_message.clear();
  if (thread_data.allocated) return;
  InitOde();
  dAllocateODEDataForThread(dAllocateMaskAll);
  thread_data.allocated = true;
}

void RenewOdeThreadData() {
  last_message.clear();
  if (thread_data.allocated) dCleanupODEAllDataForThread();
  thread_data.allocated = false;
  EnsureOdeThreadData();
}

}  // namespace armfault
