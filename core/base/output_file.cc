#include "core/base/output_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "core/base/json_input.h"

namespace armfault {

namespace {

InputError LinkRefused(const std::filesystem::path& path) {
  return InputError(path.string(), "",
                    "is a symbolic link: armfault does not write through links; remove it or choose another output "
                    "directory");
}

int OpenDescriptor(const std::filesystem::path& path, bool append) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | O_NOFOLLOW | (append ? O_APPEND : O_TRUNC), 0644);
  if (fd < 0) {
    if (errno == ELOOP) throw LinkRefused(path);
    throw InputError(path.string(), "", std::string("cannot open for writing: ") + std::strerror(errno));
  }
  return fd;
}

}  // namespace

int OpenDescriptorForWriting(const std::filesystem::path& path) { return OpenDescriptor(path, false); }

std::FILE* OpenForWriting(const std::filesystem::path& path, const char* mode) {
  const int fd = OpenDescriptor(path, std::string_view(mode) == "ab");
  std::FILE* file = ::fdopen(fd, mode);
  if (!file) {
    const int error = errno;
    ::close(fd);
    throw InputError(path.string(), "", std::string("cannot open for writing: ") + std::strerror(error));
  }
  return file;
}

void WriteChecked(std::FILE* file, std::string_view text, const std::filesystem::path& path) {
  errno = 0;
  if (std::fwrite(text.data(), 1, text.size(), file) != text.size() || std::fflush(file) != 0) {
    throw InputError(path.string(), "", std::string("cannot write: ") + std::strerror(errno ? errno : EIO));
  }
}

void CloseChecked(std::FILE* file, const std::filesystem::path& path) {
  errno = 0;
  if (std::fclose(file) != 0) {
    throw InputError(path.string(), "", std::string("cannot write: ") + std::strerror(errno ? errno : EIO));
  }
}

void RenameChecked(const std::filesystem::path& from, const std::filesystem::path& to) {
  std::error_code ec;
  std::filesystem::rename(from, to, ec);
  if (ec) throw InputError(to.string(), "", "cannot write: " + ec.message());
}

AtomicOutputFile::AtomicOutputFile(std::filesystem::path path)
    : path_(std::move(path)), tmp_(path_.string() + ".tmp"), file_(OpenForWriting(tmp_, "wb")) {}

AtomicOutputFile::~AtomicOutputFile() {
  if (!file_) return;
  std::fclose(file_);
  std::error_code ec;
  std::filesystem::remove(tmp_, ec);
}

void AtomicOutputFile::Write(std::string_view text) {
  // Buffered (no flush per write: the file counts only once committed); a failed flush of the
  // buffer shows as a short write here.
  errno = 0;
  if (std::fwrite(text.data(), 1, text.size(), file_) != text.size()) {
    throw InputError(tmp_.string(), "", std::string("cannot write: ") + std::strerror(errno ? errno : EIO));
  }
}

void AtomicOutputFile::Commit() {
  std::FILE* file = file_;
  file_ = nullptr;
  try {
    CloseChecked(file, tmp_);
    RenameChecked(tmp_, path_);
  } catch (const InputError&) {
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
    throw;
  }
}

void WriteAtomically(const std::filesystem::path& path, std::string_view text) {
  AtomicOutputFile file(path);  // never through a link placed at the .tmp name; a link at `path` is replaced
  file.Write(text);
  file.Commit();
}

void RefuseSymlink(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_symlink(std::filesystem::symlink_status(path, ec))) throw LinkRefused(path);
}

}  // namespace armfault
