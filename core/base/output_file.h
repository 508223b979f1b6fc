// Writing files safely: never through a symbolic link (a results.jsonl placed as a link to
// another file must not overwrite that file), and every write checked, so a full disk stops
// the command at once with the operating system's reason and the path, instead of results
// that end in a cut line.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

namespace armfault {

// Opens `path` for writing ("wb": created or truncated; "ab": created or appended to) without
// following a symbolic link (O_NOFOLLOW). Throws InputError naming the path: a link is refused
// ("is a symbolic link: armfault does not write through links; ..."), any other failure with
// the system's reason.
std::FILE* OpenForWriting(const std::filesystem::path& path, const char* mode);
// The same, as a file descriptor opened O_WRONLY | O_CREAT | O_TRUNC (for zlib's gzdopen).
int OpenDescriptorForWriting(const std::filesystem::path& path);

// Writes all of `text` and flushes it; throws InputError(path, "", "cannot write: <reason>")
// (e.g. "No space left on device") when the file does not take it all.
void WriteChecked(std::FILE* file, std::string_view text, const std::filesystem::path& path);

// Closes `file`; throws InputError(path, "", "cannot write: <reason>") when the last of it did
// not reach the file.
void CloseChecked(std::FILE* file, const std::filesystem::path& path);

// Renames `from` over `to` (a link at `to` is replaced itself, never followed); throws
// InputError naming `to` with the system's reason.
void RenameChecked(const std::filesystem::path& from, const std::filesystem::path& to);

// A file written whole or not at all: Write() appends to `path`.tmp (opened as OpenForWriting
// does, every write checked), Commit() closes it, checked, and renames it to `path`. Destroyed
// before Commit() (an error, an exception) it removes the .tmp: no half file is left behind.
class AtomicOutputFile {
 public:
  explicit AtomicOutputFile(std::filesystem::path path);
  ~AtomicOutputFile();
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;
  void Write(std::string_view text);
  void Commit();

 private:
  std::filesystem::path path_, tmp_;
  std::FILE* file_;
};

// Writes `text` to `path` as an AtomicOutputFile: a crash leaves the old file or the new one,
// never half of one. Throws InputError if it cannot write.
void WriteAtomically(const std::filesystem::path& path, std::string_view text);

// Throws InputError naming `path` when it is a symbolic link (for calls that would follow one,
// such as resizing a file in place).
void RefuseSymlink(const std::filesystem::path& path);

}  // namespace armfault
