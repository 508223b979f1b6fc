// Writing files: never through a symbolic link, every write checked (core/base/output_file.h).
#include "core/base/output_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/base/json_input.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing_support::ErrorOf;
using testing_support::ReadAll;
using testing_support::ScratchDir;

TEST(OutputFile, ALinkIsRefusedAndItsTargetLeftAlone) {
  ScratchDir dir("output_file");
  const std::string target = dir.Write("precious.txt", "precious\n");
  const fs::path link = dir.path() / "results.jsonl";
  fs::create_symlink(target, link);
  for (const char* mode : {"wb", "ab"}) {
    const InputError e = ErrorOf([&] { OpenForWriting(link, mode); });
    EXPECT_EQ(e.source(), link.string());
    EXPECT_THAT(e.message(), HasSubstr("is a symbolic link: armfault does not write through links"));
  }
  EXPECT_THAT(ErrorOf([&] { RefuseSymlink(link); }).message(), HasSubstr("is a symbolic link"));
  EXPECT_EQ(ReadAll(target), "precious\n");
  EXPECT_NO_THROW(RefuseSymlink(target));
}

TEST(OutputFile, WritesAndAppends) {
  ScratchDir dir("output_file");
  const fs::path path = dir.path() / "a.txt";
  CloseChecked(OpenForWriting(path, "wb"), path);
  std::FILE* f = OpenForWriting(path, "ab");
  WriteChecked(f, "one\n", path);
  CloseChecked(f, path);
  f = OpenForWriting(path, "ab");
  WriteChecked(f, "two\n", path);
  CloseChecked(f, path);
  EXPECT_EQ(ReadAll(path), "one\ntwo\n");
}

TEST(OutputFile, AFullDiskIsNamedWithTheSystemsReason) {
  // /dev/full takes nothing: every write fails with ENOSPC, as a full file system does.
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  std::FILE* f = OpenForWriting("/dev/full", "wb");
  const InputError e = ErrorOf([&] { WriteChecked(f, std::string(8192, 'x'), "/dev/full"); });
  std::fclose(f);
  EXPECT_EQ(e.source(), "/dev/full");
  EXPECT_EQ(e.message(), "cannot write: No space left on device");
}

TEST(AtomicOutputFile, AppearsWholeOnCommitAndNotAtAllOtherwise) {
  ScratchDir dir("output_file");
  const fs::path path = dir.path() / "summary.json";
  {
    AtomicOutputFile file(path);
    file.Write("{\n");
    EXPECT_FALSE(fs::exists(path));  // only the .tmp so far
    file.Write("}\n");
    file.Commit();
  }
  EXPECT_EQ(ReadAll(path), "{\n}\n");
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
  {
    AtomicOutputFile file(path);
    file.Write("half");  // an error before Commit(): the old file stays, no .tmp is left
  }
  EXPECT_EQ(ReadAll(path), "{\n}\n");
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
  // A link at the .tmp name is refused, its target left alone.
  const std::string target = dir.Write("precious.txt", "precious\n");
  fs::create_symlink(target, path.string() + ".tmp");
  EXPECT_THAT(ErrorOf([&] { AtomicOutputFile file(path); }).message(), HasSubstr("is a symbolic link"));
  EXPECT_EQ(ReadAll(target), "precious\n");
}

// In a child process (so the limit binds no other test): a file-size limit makes the kernel
// refuse the write (EFBIG) as a full disk refuses one (ENOSPC). Exits 0 when the error names the
// .tmp and the reason and nothing is left behind.
[[noreturn]] void WriteBeyondAFileSizeLimit(const fs::path& path) {
  std::signal(SIGXFSZ, SIG_IGN);
  rlimit limit;
  limit.rlim_cur = limit.rlim_max = 4096;
  setrlimit(RLIMIT_FSIZE, &limit);
  bool named = false;
  try {
    AtomicOutputFile file(path);
    for (int i = 0; i < 100; ++i) file.Write(std::string(1000, 'x'));
    file.Commit();
  } catch (const InputError& e) {
    named = e.source() == path.string() + ".tmp" && e.message() == "cannot write: File too large";
  }
  std::exit(named && !fs::exists(path) && !fs::exists(path.string() + ".tmp") ? 0 : 1);
}

TEST(AtomicOutputFile, AWriteThatFailsIsNamedAndLeavesNoTmp) {
  ScratchDir dir("output_file");
  EXPECT_EXIT(WriteBeyondAFileSizeLimit(dir.path() / "results.csv"), testing::ExitedWithCode(0), "");
}

}  // namespace
}  // namespace armfault
