// Strict reading of JSON input: every error names the source, the JSON pointer
// of the offending value and the value itself, so a user can find it at once.
#pragma once

#include <nlohmann/json.hpp>

#include <set>
#include <stdexcept>
#include <initializer_list>
#include <cmath>
#include <string>
#include <vector>

namespace armfault {

// Invalid user input (a file, a command-line value). The CLI turns it into
// exit status 2. what() reads "<source>: <pointer>: <message>".
class InputError : public std::runtime_error {
 public:
  InputError(std::string source, std::string pointer, std::string message);

  const std::string& source() const { return source_; }
  const std::string& pointer() const { return pointer_; }
  const std::string& message() const { return message_; }

  // The same error attributed to `source` (used where a parser did not know the file name).
  InputError WithSource(const std::string& source) const;

 private:
  std::string source_, pointer_, message_;
};

// A number for messages: up to 12 significant digits, no trailing zeros ("0.5", "1e-07").
std::string FormatNumber(double x);
// A time rounded to the microsecond, the precision armfault's clocks have: written files say
// 3.788, not 3.7880000000000003. Idempotent, so a value read back rounds to itself.
inline double RoundToMicroseconds(double t_s) { return std::round(t_s * 1e6) / 1e6; }

// Compact rendering of a JSON value for error messages (long values are cut).
std::string Describe(const nlohmann::json& value);

// Appends an unescaped token to a JSON pointer string, escaping '~' and '/'.
std::string PointerJoin(const std::string& pointer, const std::string& token);
inline std::string PointerJoin(const std::string& pointer, size_t index) {
  return pointer + "/" + std::to_string(index);
}

// Reads one JSON object field by field and remembers which keys were read,
// so that Finish() can reject any key nobody asked for.
class ObjectReader {
 public:
  // Throws InputError if `object` is not a JSON object.
  ObjectReader(const nlohmann::json& object, std::string pointer);

  bool Has(const std::string& key) const;
  // The raw value of `key` (marked as used), or nullptr if absent.
  const nlohmann::json* Find(const std::string& key);
  const nlohmann::json& Require(const std::string& key);

  // Typed reads. Optional* leave *out unchanged when the key is absent.
  void OptionalNumber(const std::string& key, double* out);
  double RequireNumber(const std::string& key);
  void OptionalInt(const std::string& key, int* out);
  int RequireInt(const std::string& key);
  void OptionalBool(const std::string& key, bool* out);
  void OptionalString(const std::string& key, std::string* out);
  std::string RequireString(const std::string& key);

  std::string PointerTo(const std::string& key) const { return PointerJoin(pointer_, key); }
  const std::string& pointer() const { return pointer_; }
  const nlohmann::json& object() const { return object_; }

  // Rejects the first key (in document order) that was never read.
  void Finish() const;
  // Marks `keys` as known and rejects any other key now, before values are checked, so a
  // misspelt key is reported as such rather than as a missing or defaulted one.
  void AllowOnly(std::initializer_list<const char*> keys);
  void AllowOnly(const std::vector<std::string>& keys);

 private:
  const nlohmann::json& object_;
  std::string pointer_;
  std::set<std::string> used_;
};

// Value checks: throw InputError(pointer, "<value> ...") when violated.
double AsNumber(const nlohmann::json& value, const std::string& pointer);
int AsInt(const nlohmann::json& value, const std::string& pointer);
std::string AsString(const nlohmann::json& value, const std::string& pointer);
void RequireAtLeast(double value, double min, const std::string& pointer);
void RequireAbove(double value, double min, const std::string& pointer);
void RequireInRange(double value, double min, double max, const std::string& pointer);

// Parses JSON text; syntax errors, empty or absurdly nested input become an InputError
// naming `source`. Maximum nesting depth: 64.
nlohmann::json ParseJsonText(const std::string& text, const std::string& source);
// Reads and parses a file; a missing or unreadable file is an InputError too.
nlohmann::json ReadJsonFile(const std::string& path);
// Reads a whole text file; throws InputError if it cannot be read.
std::string ReadTextFile(const std::string& path);

}  // namespace armfault
