// Writing files safely: never through a symbolic link (a results.jsonl placed as a link to
// another file must not overwrite that file), and every write checked, so a full disk stops
// the command at once with the operating system's reason and the path, instead of results
// that end in a cut line.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string_view>

namespace armfault {

// Opens `path` for writing ("wb": created or truncated; "ab": created or appended to) without
// following a symbolic link (O_NOFOLLOW). Throws InputError naming the path: a link is refused
// ("is a symbolic link: armfault does not write through links; ..."), any other failure with
// the system's reason.
std::FILE* OpenForWriting(const std::filesystem::path& path, const char* mode);

// Writes all of `text` and flushes it; throws InputError(path, "", "cannot write: <reason>")
// (e.g. "No space left on device") when the file does not take it all.
void WriteChecked(std::FILE* file, std::string_view text, const std::filesystem::path& path);

// Closes `file`; throws InputError(path, "", "cannot write: <reason>") when the last of it did
// not reach the file.
void CloseChecked(std::FILE* file, const std::filesystem::path& path);

// Throws InputError naming `path` when it is a symbolic link (for calls that would follow one,
// such as resizing a file in place).
void RefuseSymlink(const std::filesystem::path& path);

}  // namespace armfault
