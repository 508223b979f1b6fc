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

}  // namespace

std::FILE* OpenForWriting(const std::filesystem::path& path, const char* mode) {
  const bool append = std::string_view(mode) == "ab";
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | O_NOFOLLOW | (append ? O_APPEND : O_TRUNC), 0644);
  if (fd < 0) {
    if (errno == ELOOP) throw LinkRefused(path);
    throw InputError(path.string(), "", std::string("cannot open for writing: ") + std::strerror(errno));
  }
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

void RefuseSymlink(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_symlink(std::filesystem::symlink_status(path, ec))) throw LinkRefused(path);
}

}  // namespace armfault
