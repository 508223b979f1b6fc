// Strict reading of JSON input: every error names the source, the JSON pointer
// of the offending value and the value itself, so a user can find it at once.
#pragma once

#include <nlohmann/json.hpp>

#include <functional>
#include <memory>
#include <set>
#include <stdexcept>
#include <initializer_list>
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

namespace armfault {

// Where a JSON value came from: the file name (for errors) and the directory against which
// relative paths inside it (a csv trajectory's "path", a plugin library) are resolved.
struct InputContext {
  std::string source = "<input>";
  std::string base_dir = ".";
};

// Invalid user input (a file, a command-line value). The CLI turns it into
// exit status 2. what() reads "<source>: <pointer>: <message>".
//
// One InputError may also stand for several errors found in one input (ErrorList): it then
// reads as the first of them, and errors() gives them all, so a caller that only knows about
// one error still gets the first, exactly as before.
class InputError : public std::runtime_error {
 public:
  // `hint` is advice printed after the message ("did you mean ...?"); it is not part of
  // what(), so the message stays the same whether a hint is found or not.
  InputError(std::string source, std::string pointer, std::string message, std::string hint = "");
  // The errors in `errors` (each flattened, repeats dropped) as one; `errors` must not be empty.
  // `unlisted`: more errors found but not kept (a reader that stops keeping them after the
  // first kMaxReportedErrors, so that a file of a million bad lines does not hold a million
  // messages); the command line counts them in its "... and N more errors".
  explicit InputError(const std::vector<InputError>& errors, size_t unlisted = 0);

  const std::string& source() const { return source_; }
  const std::string& pointer() const { return pointer_; }
  const std::string& message() const { return message_; }
  const std::string& hint() const { return hint_; }
  // what() followed by "; <hint>" when there is one: the line the command line prints.
  std::string text() const;

  // Every error this one stands for, in the order found: itself, or all that were collected.
  std::vector<InputError> errors() const;
  size_t count() const { return (all_ ? all_->size() : 1) + unlisted_; }
  size_t unlisted() const { return unlisted_; }  // errors counted but not held (not in errors())

  // The same error(s), each without a source attributed to `source` (used where a parser did
  // not know the file name); errors that already name a file keep it.
  InputError WithSource(const std::string& source) const;
  // The same error(s) with each one's source, pointer or message rewritten by `edit`.
  InputError Edited(const std::function<void(std::string* source, std::string* pointer, std::string* message)>& edit) const;

 private:
  InputError(std::vector<InputError> flat, size_t unlisted, int);
  static std::vector<InputError> Flatten(const std::vector<InputError>& errors);
  static size_t UnlistedOf(const std::vector<InputError>& errors);

  std::string source_, pointer_, message_, hint_;
  std::shared_ptr<const std::vector<InputError>> all_;  // null: a single error; else >= 2 single ones
  size_t unlisted_ = 0;
};

// Collects the errors of the independent parts of one input, so a user sees every mistake in
// a file at once instead of one per attempt. A parser runs each part through Try(), keeps
// going after a part fails, skips only the checks that need the failed part, and ends with
// ThrowIfAny(). Parts may themselves throw several errors (a nested collecting parser).
class ErrorList {
 public:
  // Runs `part`; an InputError it throws is recorded. Returns false if it threw, so the caller
  // can skip what depends on the part. Other exceptions pass through.
  template <class F>
  bool Try(F&& part) {
    try {
      part();
      return true;
    } catch (const InputError& e) {
      Add(e);
      return false;
    }
  }
  // Records every error `e` stands for; one already recorded (same source, pointer and
  // message, as when two checks trip over the same bad value) is dropped.
  void Add(const InputError& e);
  bool empty() const { return errors_.empty(); }
  size_t size() const { return errors_.size(); }
  const std::vector<InputError>& errors() const { return errors_; }
  // Throws the collected errors as one InputError; does nothing when there are none.
  void ThrowIfAny() const;

 private:
  std::vector<InputError> errors_;
  size_t unlisted_ = 0;  // the added errors' unlisted counts
  std::set<std::tuple<std::string, std::string, std::string>> seen_;  // source, pointer, message
};

// How many errors the command line prints before "... and N more".
constexpr size_t kMaxReportedErrors = 20;
// The lines the command line prints for `e` (without its "armfault: error: " prefix): one
// text() per error, at most `limit`, then "... and N more errors" for the rest.
std::vector<std::string> ErrorReportLines(const InputError& e, size_t limit = kMaxReportedErrors);

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
  // Whether a parser that reports every key's errors at once should read `key`: it is
  // present, or every key of the object is known (read or allowed). A key missing beside an
  // unknown one is not reported as missing: the unknown one is probably it, misspelt.
  bool ShouldRead(const std::string& key) const;
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

  // Rejects every key that was never read, each as its own error (in document order), with
  // the nearest known key as a "did you mean" hint.
  void Finish() const;
  // Marks `keys` as known and rejects any other key now, before values are checked, so a
  // misspelt key is reported as such rather than as a missing or defaulted one.
  void AllowOnly(std::initializer_list<const char*> keys);
  void AllowOnly(const std::vector<std::string>& keys);

 private:
  const nlohmann::json& object_;
  std::string pointer_;
  std::set<std::string> used_;
  std::set<std::string> asked_;  // every key looked up, present or not: candidates for hints
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

// JSON Lines read strictly: each line of `path` parsed and handed to `each` with its number
// (from 1). A line that does not parse, or that `each` refuses by throwing, is an InputError
// "PATH: line N: why", except an InputError that names a file of its own (one read in step
// with this one), which passes as it is; a file that cannot be opened is "PATH: <open_error>". Lines of only
// white space are skipped when `skip_blank` is set, else they are errors like any other.
struct JsonLinesOptions {
  std::string open_error = "cannot read the file";
  bool skip_blank = false;
};
void ReadJsonLines(const std::string& path, const JsonLinesOptions& options,
                   const std::function<void(nlohmann::json&& line, long number)>& each);
// Reads a whole text file; throws InputError if it cannot be read.
std::string ReadTextFile(const std::string& path);

}  // namespace armfault
