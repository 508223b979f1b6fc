#include "core/base/json_input.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "core/base/suggest.h"

namespace armfault {

namespace {
std::string FormatWhat(const std::string& source, const std::string& pointer,
                       const std::string& message) {
  std::string out;
  if (!source.empty()) out += source + ": ";
  // An option or an environment variable has no document: its name says where. Neither does a
  // line of a JSON Lines file: its number says where.
  const bool not_a_document =
      pointer.empty() && ((!source.empty() && (source[0] == '-' ||
                                               source.find_first_of("abcdefghijklmnopqrstuvwxyz./") == std::string::npos)) ||
                          message.rfind("line ", 0) == 0);
  if (!not_a_document) out += (pointer.empty() ? std::string("(document root)") : pointer) + ": ";
  out += message;
  return out;
}

std::string TypeName(const nlohmann::json& v) { return v.type_name(); }
}  // namespace

InputError::InputError(std::string source, std::string pointer, std::string message, std::string hint)
    : std::runtime_error(FormatWhat(source, pointer, message)),
      source_(std::move(source)),
      pointer_(std::move(pointer)),
      message_(std::move(message)),
      hint_(std::move(hint)) {}

InputError::InputError(const std::vector<InputError>& errors, size_t unlisted)
    : InputError(Flatten(errors), unlisted + UnlistedOf(errors), 0) {}

size_t InputError::UnlistedOf(const std::vector<InputError>& errors) {
  size_t n = 0;
  for (const InputError& e : errors) n += e.unlisted_;
  return n;
}

// Members are set in declaration order, so `flat` is moved into all_ only after its first
// element was copied into the others.
InputError::InputError(std::vector<InputError> flat, size_t unlisted, int)
    : std::runtime_error(flat.at(0).what()),
      source_(flat[0].source_),
      pointer_(flat[0].pointer_),
      message_(flat[0].message_),
      hint_(flat[0].hint_),
      all_(flat.size() > 1 ? std::make_shared<const std::vector<InputError>>(std::move(flat)) : nullptr),
      unlisted_(unlisted) {}

std::vector<InputError> InputError::Flatten(const std::vector<InputError>& errors) {
  ErrorList list;
  for (const InputError& e : errors) list.Add(e);
  return list.errors();
}

std::string InputError::text() const { return hint_.empty() ? std::string(what()) : what() + ("; " + hint_); }

std::vector<InputError> InputError::errors() const {
  if (all_) return *all_;
  return {InputError(source_, pointer_, message_, hint_)};
}

InputError InputError::WithSource(const std::string& source) const {
  return Edited([&](std::string* s, std::string*, std::string*) {
    if (s->empty()) *s = source;
  });
}

InputError InputError::Edited(
    const std::function<void(std::string* source, std::string* pointer, std::string* message)>& edit) const {
  std::vector<InputError> out;
  for (const InputError& e : errors()) {
    std::string source = e.source_, pointer = e.pointer_, message = e.message_;
    edit(&source, &pointer, &message);
    out.emplace_back(std::move(source), std::move(pointer), std::move(message), e.hint_);
  }
  return InputError(out, unlisted_);
}

void ErrorList::Add(const InputError& e) {
  for (InputError& one : e.errors()) {
    if (seen_.emplace(one.source(), one.pointer(), one.message()).second) errors_.push_back(std::move(one));
  }
  unlisted_ += e.unlisted();
}

void ErrorList::ThrowIfAny() const {
  if (!errors_.empty()) throw InputError(errors_, unlisted_);
}

std::vector<std::string> ErrorReportLines(const InputError& e, size_t limit) {
  std::vector<std::string> lines;
  const std::vector<InputError> all = e.errors();
  for (size_t i = 0; i < all.size() && i < limit; ++i) lines.push_back(all[i].text());
  const size_t rest = all.size() - lines.size() + e.unlisted();
  if (rest > 0) lines.push_back("... and " + std::to_string(rest) + " more errors");
  return lines;
}

std::string Describe(const nlohmann::json& value) {
  std::string text = value.dump();
  constexpr size_t kMax = 60;
  if (text.size() > kMax) text = text.substr(0, kMax) + "...";
  return text;
}

std::string PointerJoin(const std::string& pointer, const std::string& token) {
  std::string escaped;
  for (char c : token) {
    if (c == '~') escaped += "~0";
    else if (c == '/') escaped += "~1";
    else escaped += c;
  }
  return pointer + "/" + escaped;
}

ObjectReader::ObjectReader(const nlohmann::json& object, std::string pointer)
    : object_(object), pointer_(std::move(pointer)) {
  if (!object_.is_object()) {
    throw InputError("", pointer_,
                     "expected an object, got " + TypeName(object_) + " " + Describe(object_));
  }
}

bool ObjectReader::Has(const std::string& key) const { return object_.contains(key); }

bool ObjectReader::ShouldRead(const std::string& key) const {
  if (Has(key)) return true;
  for (auto it = object_.begin(); it != object_.end(); ++it) {
    if (used_.count(it.key()) == 0) return false;
  }
  return true;
}

const nlohmann::json* ObjectReader::Find(const std::string& key) {
  asked_.insert(key);
  auto it = object_.find(key);
  if (it == object_.end()) return nullptr;
  used_.insert(key);
  return &*it;
}

const nlohmann::json& ObjectReader::Require(const std::string& key) {
  const nlohmann::json* v = Find(key);
  if (v == nullptr) throw InputError("", PointerTo(key), "required key is missing");
  return *v;
}

void ObjectReader::OptionalNumber(const std::string& key, double* out) {
  if (const nlohmann::json* v = Find(key)) *out = AsNumber(*v, PointerTo(key));
}
double ObjectReader::RequireNumber(const std::string& key) {
  return AsNumber(Require(key), PointerTo(key));
}
void ObjectReader::OptionalInt(const std::string& key, int* out) {
  if (const nlohmann::json* v = Find(key)) *out = AsInt(*v, PointerTo(key));
}
int ObjectReader::RequireInt(const std::string& key) { return AsInt(Require(key), PointerTo(key)); }
void ObjectReader::OptionalBool(const std::string& key, bool* out) {
  if (const nlohmann::json* v = Find(key)) {
    if (!v->is_boolean()) {
      throw InputError("", PointerTo(key), "expected true or false, got " + Describe(*v));
    }
    *out = v->get<bool>();
  }
}
void ObjectReader::OptionalString(const std::string& key, std::string* out) {
  if (const nlohmann::json* v = Find(key)) *out = AsString(*v, PointerTo(key));
}
std::string ObjectReader::RequireString(const std::string& key) {
  return AsString(Require(key), PointerTo(key));
}

void ObjectReader::Finish() const {
  std::vector<std::string> known(used_.begin(), used_.end());
  for (const std::string& key : asked_) {
    if (!used_.count(key)) known.push_back(key);
  }
  ErrorList errors;
  for (auto it = object_.begin(); it != object_.end(); ++it) {
    if (used_.count(it.key()) != 0) continue;
    const std::string near = NearestWord(it.key(), known);
    errors.Add(InputError("", PointerTo(it.key()), "unknown key \"" + it.key() + "\"",
                          near.empty() ? "" : "did you mean \"" + near + "\"?"));
  }
  errors.ThrowIfAny();
}

void ObjectReader::AllowOnly(std::initializer_list<const char*> keys) {
  for (const char* key : keys) used_.insert(key);
  Finish();
}

void ObjectReader::AllowOnly(const std::vector<std::string>& keys) {
  for (const std::string& key : keys) used_.insert(key);
  Finish();
}

double AsNumber(const nlohmann::json& value, const std::string& pointer) {
  if (!value.is_number()) {
    throw InputError("", pointer, "expected a number, got " + TypeName(value) + " " + Describe(value));
  }
  double x = value.get<double>();
  if (!std::isfinite(x)) throw InputError("", pointer, "expected a finite number, got " + Describe(value));
  return x;
}

int AsInt(const nlohmann::json& value, const std::string& pointer) {
  double x = AsNumber(value, pointer);
  if (x != std::floor(x) || std::fabs(x) > 2e9) {
    throw InputError("", pointer, "expected a whole number, got " + Describe(value));
  }
  return static_cast<int>(x);
}

std::string AsString(const nlohmann::json& value, const std::string& pointer) {
  if (!value.is_string()) {
    throw InputError("", pointer, "expected a string, got " + TypeName(value) + " " + Describe(value));
  }
  return value.get<std::string>();
}

std::string FormatNumber(double x) {
  std::ostringstream s;
  s.precision(12);
  s << x;
  return s.str();
}

void RequireAtLeast(double value, double min, const std::string& pointer) {
  if (!(value >= min)) throw InputError("", pointer, FormatNumber(value) + " is below the minimum " + FormatNumber(min));
}
void RequireAbove(double value, double min, const std::string& pointer) {
  if (!(value > min)) throw InputError("", pointer, FormatNumber(value) + " must be greater than " + FormatNumber(min));
}
void RequireInRange(double value, double min, double max, const std::string& pointer) {
  if (!(value >= min && value <= max)) {
    throw InputError("", pointer, FormatNumber(value) + " is outside [" + FormatNumber(min) + ", " + FormatNumber(max) + "]");
  }
}

namespace {

// Builds the document as nlohmann's own parser does (the same values, bit for bit) while it
// knows the JSON pointer of every value, so that what the parser alone would let through or
// abort on is an InputError naming the file and the field: a key given twice in one object
// (nlohmann keeps the last), a number beyond a double (nlohmann throws out_of_range.406, which
// its callback parser lets escape as std::terminate), nesting deeper than kMaxDepth.
class PointerSax : public nlohmann::json_sax<nlohmann::json> {
 public:
  static constexpr size_t kMaxDepth = 64;
  explicit PointerSax(std::string source) : source_(std::move(source)) {}

  bool null() override { return Put(nullptr); }
  bool boolean(bool v) override { return Put(v); }
  bool number_integer(number_integer_t v) override { return Put(v); }
  bool number_unsigned(number_unsigned_t v) override { return Put(v); }
  bool number_float(number_float_t v, const string_t&) override { return Put(v); }
  bool string(string_t& v) override { return Put(std::move(v)); }
  bool binary(binary_t& v) override { return Put(nlohmann::json::binary(std::move(v))); }
  bool start_object(std::size_t) override { return Open(nlohmann::json::object()); }
  bool start_array(std::size_t) override { return Open(nlohmann::json::array()); }
  bool end_object() override { return Close(); }
  bool end_array() override { return Close(); }
  bool key(string_t& k) override {
    Frame& f = frames_.back();
    f.key = k;
    if (f.value->contains(k)) {
      return Fail(InputError(source_, ValuePointer(), "the key \"" + k + "\" is given twice in one object"));
    }
    return true;
  }
  bool parse_error(std::size_t, const std::string& token, const nlohmann::detail::exception& e) override {
    if (e.id == 406) {  // out_of_range: a number beyond a double
      return Fail(InputError(source_, ValuePointer(), "the number " + token + " is beyond the range of a double"));
    }
    const std::string what = e.what();
    // nlohmann's message starts with "[json.exception.parse_error.101] "; keep the rest.
    const auto pos = what.find("] ");
    return Fail(InputError(source_, "", "not valid JSON: " + (pos == std::string::npos ? what : what.substr(pos + 2))));
  }

  nlohmann::json Result() {
    if (error_) throw *error_;
    return std::move(root_);
  }

 private:
  struct Frame {
    nlohmann::json* value;
    std::string pointer;  // of the container
    std::string key;      // an object's current key
  };

  // The pointer of the value about to be put into the innermost container.
  std::string ValuePointer() const {
    if (frames_.empty()) return "";
    const Frame& f = frames_.back();
    return f.value->is_array() ? PointerJoin(f.pointer, f.value->size()) : PointerJoin(f.pointer, f.key);
  }
  nlohmann::json* Put(nlohmann::json v) {
    if (frames_.empty()) {
      root_ = std::move(v);
      return &root_;
    }
    Frame& f = frames_.back();
    if (f.value->is_array()) {
      f.value->push_back(std::move(v));
      return &f.value->back();
    }
    nlohmann::json& slot = (*f.value)[f.key];
    slot = std::move(v);
    return &slot;
  }
  bool Open(nlohmann::json container) {
    if (frames_.size() >= kMaxDepth) {
      return Fail(InputError(source_, "", "nesting deeper than " + std::to_string(kMaxDepth) + " levels"));
    }
    const std::string pointer = ValuePointer();
    frames_.push_back({Put(std::move(container)), pointer, ""});
    return true;
  }
  bool Close() {
    frames_.pop_back();
    return true;
  }
  bool Fail(InputError e) {
    if (!error_) error_ = std::move(e);
    return false;
  }

  std::string source_;
  nlohmann::json root_;
  std::vector<Frame> frames_;
  std::optional<InputError> error_;
};

}  // namespace

nlohmann::json ParseJsonText(const std::string& text, const std::string& source) {
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) {
    throw InputError(source, "", "the input is empty, expected a JSON document");
  }
  PointerSax sax(source);
  nlohmann::json::sax_parse(text, &sax);
  return sax.Result();
}

std::string ReadTextFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, "", "is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot open the file for reading");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw InputError(path, "", "error while reading the file");
  return buffer.str();
}

nlohmann::json ReadJsonFile(const std::string& path) { return ParseJsonText(ReadTextFile(path), path); }

void ReadJsonLines(const std::string& path, const JsonLinesOptions& options,
                   const std::function<void(nlohmann::json&& line, long number)>& each) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", options.open_error);
  std::string line;
  long n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (options.skip_blank && line.find_first_not_of(" \t\r") == std::string::npos) continue;
    try {
      each(nlohmann::json::parse(line), n);
    } catch (const InputError& e) {
      if (!e.source().empty()) throw;  // about another file (one read in step): as it is
      throw InputError(path, "", "line " + std::to_string(n) + ": " + e.what());
    } catch (const std::exception& e) {
      throw InputError(path, "", "line " + std::to_string(n) + ": " + e.what());
    }
  }
}

}  // namespace armfault
