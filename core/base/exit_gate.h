// Ending the process from a signal handler without cutting a record in two. A second Ctrl-C
// must stop a run at once (not after the runs in flight), yet every line already written must
// stay whole: the writer holds the gate while it writes one run's lines, and an exit asked for
// meanwhile happens as it lets go. Lock-free atomics, write(2) and _exit only, so RequestExit
// is async-signal-safe.
#pragma once

#include <atomic>
#include <cstddef>

namespace armfault {

class ExitGate {
 public:
  // The writer, around one record's lines (one writer at a time). Leave() ends the process
  // when RequestExit() came while it was inside.
  void Enter();
  void Leave();
  // From a signal handler: prints `message` (kept alive by the caller) to stderr and ends the
  // process with `status`, at once or, when the writer is inside, as it leaves.
  void RequestExit(int status, const char* message, std::size_t length);
  // A file the process removes as it ends here (the output directory's lock file: a lock left
  // behind would name a writer that is gone); `path` is kept alive by the caller, nullptr: none.
  void RemoveOnExit(const char* path) { remove_on_exit_.store(path); }

 private:
  [[noreturn]] void ExitNow();
  enum State : int { kIdle, kWriting, kExiting };
  std::atomic<int> state_{kIdle};
  std::atomic<bool> pending_{false};
  std::atomic<int> status_{0};
  std::atomic<const char*> message_{nullptr};
  std::atomic<std::size_t> length_{0};
  std::atomic<const char*> remove_on_exit_{nullptr};
};

}  // namespace armfault
