// Why zlib stopped reading a gzip (or plain) file, for an error that names the file itself.
#pragma once

#include <zlib.h>

#include <string>

namespace armfault {

// zlib's message for `file`'s last error (Z_OK in *code: none), without the "PATH: " zlib puts
// before it, and with " (cut short or corrupt)" when the data, not the system, is the cause:
// a stream cut short (Z_BUF_ERROR: zlib gives the data it could decode, then 0) or damaged.
inline std::string GzipReason(gzFile file, const std::string& path, int* code) {
  std::string why = gzerror(file, code);
  if (const std::string prefix = path + ": "; why.rfind(prefix, 0) == 0) why.erase(0, prefix.size());
  if (*code != Z_OK && *code != Z_ERRNO) why += " (cut short or corrupt)";
  return why;
}

}  // namespace armfault
