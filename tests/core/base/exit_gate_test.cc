// ExitGate (core/base/exit_gate.h): an exit asked for while the writer is inside waits for it.
#include "core/base/exit_gate.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

namespace armfault {
namespace {

[[noreturn]] void ExitInsideTheGate() {
  ExitGate gate;
  static const char kMessage[] = "stopped\n";
  gate.Enter();
  gate.RequestExit(7, kMessage, sizeof kMessage - 1);  // as a handler would, mid-write
  std::fputs("the record's end\n", stderr);            // still written: the exit waits
  std::fflush(stderr);
  gate.Leave();  // exits here
  std::exit(1);
}

[[noreturn]] void ExitOutsideTheGate() {
  ExitGate gate;
  static const char kMessage[] = "stopped\n";
  gate.Enter();
  gate.Leave();
  gate.RequestExit(7, kMessage, sizeof kMessage - 1);  // exits at once
  std::fputs("never\n", stderr);
  std::exit(1);
}

TEST(ExitGate, AnExitWaitsForTheWriterToLeave) {
  EXPECT_EXIT(ExitInsideTheGate(), testing::ExitedWithCode(7), "the record's end\nstopped\n");
  EXPECT_EXIT(ExitOutsideTheGate(), testing::ExitedWithCode(7), "^stopped\n$");
}

}  // namespace
}  // namespace armfault
