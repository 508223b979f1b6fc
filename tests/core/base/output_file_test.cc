// Writing files: never through a symbolic link, every write checked (core/base/output_file.h).
#include "core/base/output_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace armfault
