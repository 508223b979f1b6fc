#include "core/base/exit_gate.h"

#include <unistd.h>

namespace armfault {

static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free &&
                  std::atomic<const char*>::is_always_lock_free,
              "a signal handler may only use lock-free atomics");

void ExitGate::Enter() {
  for (;;) {
    int expected = kIdle;
    if (state_.compare_exchange_strong(expected, kWriting)) return;
    // kExiting: a handler on another thread is ending the process; write nothing more.
    if (expected == kExiting) {
      for (;;) ::pause();
    }
  }
}

void ExitGate::Leave() {
  state_.store(kIdle);
  if (!pending_.load()) return;
  int expected = kIdle;
  if (state_.compare_exchange_strong(expected, kExiting)) ExitNow();
}

void ExitGate::RequestExit(int status, const char* message, std::size_t length) {
  status_.store(status);
  message_.store(message);
  length_.store(length);
  int expected = kIdle;
  if (state_.compare_exchange_strong(expected, kExiting)) ExitNow();
  // The writer is inside: it exits as it leaves. Unless it left in between: then exit here.
  pending_.store(true);
  expected = kIdle;
  if (state_.compare_exchange_strong(expected, kExiting)) ExitNow();
}

void ExitGate::ExitNow() {
  if (const char* path = remove_on_exit_.load(); path != nullptr) ::unlink(path);
  const char* message = message_.load();
  if (message != nullptr) {
    const ssize_t ignored = ::write(STDERR_FILENO, message, length_.load());
    (void)ignored;
  }
  ::_exit(status_.load());
}

}  // namespace armfault
