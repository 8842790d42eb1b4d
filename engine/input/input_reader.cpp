#include "engine/input/input_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "engine/input/field_table.hpp"

namespace flocsim::input {

namespace {
std::string format_number(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}
}  // namespace

std::string Range::describe() const {
  std::vector<std::string> parts;
  if (at_least) parts.push_back(">= " + format_number(*at_least));
  if (above) parts.push_back("> " + format_number(*above));
  if (at_most) parts.push_back("<= " + format_number(*at_most));
  if (below) parts.push_back("< " + format_number(*below));
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) out += (i ? " and " : "") + parts[i];
  if (out.empty()) out = "any finite number";
  if (!why.empty()) out += " " + why;
  return out;
}

bool Range::contains(double v) const {
  if (!std::isfinite(v)) return false;
  if (at_least && !(v >= *at_least)) return false;
  if (above && !(v > *above)) return false;
  if (at_most && !(v <= *at_most)) return false;
  if (below && !(v < *below)) return false;
  return true;
}

InputReader::InputReader(const nlohmann::json& object, std::string path)
    : object_(object), path_(std::move(path)) {
  if (!object_.is_object())
    throw InputError((path_.empty() ? std::string("input") : path_) + " = " + shown(object_) +
                     ": must be a JSON object");
}

bool InputReader::has(const std::string& key) const {
  return object_.contains(key);
}

const nlohmann::json* InputReader::find(const std::string& key) {
  known_.push_back(key);
  auto it = object_.find(key);
  return it == object_.end() ? nullptr : &*it;
}

double InputReader::number(const std::string& key, const Range& range,
                           std::optional<double> fallback) {
  const nlohmann::json* v = find(key);
  if (!v) {
    if (fallback) return *fallback;
    throw InputError(field(key) + " is missing: a number " + range.describe() + " is required");
  }
  if (!v->is_number())
    throw InputError(field(key) + " = " + shown(*v) + ": must be a number " + range.describe());
  const double x = v->get<double>();
  if (!range.contains(x))
    throw InputError(field(key) + " = " + exact_number(x) + ": must be " + range.describe());
  return x;
}

long InputReader::integer(const std::string& key, const Range& range,
                          std::optional<long> fallback) {
  const nlohmann::json* v = find(key);
  if (!v) {
    if (fallback) return *fallback;
    throw InputError(field(key) + " is missing: an integer " + range.describe() + " is required");
  }
  long x = 0;
  if (v->is_number() && !range.contains(v->get<double>()))  // 1e20: out of range, not a fraction
    throw InputError(field(key) + " = " + shown(*v) + ": must be " + range.describe());
  if (!whole_number(*v, x))
    throw InputError(field(key) + " = " + shown(*v) + ": must be a whole number " +
                     range.describe());
  if (!range.contains(static_cast<double>(x)))
    throw InputError(field(key) + " = " + std::to_string(x) + ": must be " + range.describe());
  return x;
}

bool InputReader::boolean(const std::string& key, std::optional<bool> fallback) {
  const nlohmann::json* v = find(key);
  if (!v) {
    if (fallback) return *fallback;
    throw InputError(field(key) + " is missing: true or false is required");
  }
  if (!v->is_boolean())
    throw InputError(field(key) + " = " + shown(*v) + ": must be true or false");
  return v->get<bool>();
}

std::string InputReader::text(const std::string& key, std::optional<std::string> fallback) {
  const nlohmann::json* v = find(key);
  if (!v) {
    if (fallback) return *fallback;
    throw InputError(field(key) + " is missing: a string is required");
  }
  if (!v->is_string()) throw InputError(field(key) + " = " + shown(*v) + ": must be a string");
  return v->get<std::string>();
}

std::string InputReader::choice(const std::string& key, const std::vector<std::string>& allowed,
                                std::optional<std::string> fallback) {
  std::string list;
  for (std::size_t i = 0; i < allowed.size(); ++i)
    list += (i ? ", " : "") + ("\"" + allowed[i] + "\"");
  const nlohmann::json* v = find(key);
  if (!v) {
    if (fallback) return *fallback;
    throw InputError(field(key) + " is missing: one of " + list + " is required");
  }
  if (!v->is_string() ||
      std::find(allowed.begin(), allowed.end(), v->get<std::string>()) == allowed.end())
    throw InputError(field(key) + " = " + shown(*v) + ": must be one of " + list);
  return v->get<std::string>();
}

std::vector<double> InputReader::numbers(const std::string& key, std::size_t length,
                                         const Range& range,
                                         std::optional<std::vector<double>> fallback) {
  const nlohmann::json* v = find(key);
  if (!v) {
    if (fallback) return *fallback;
    throw InputError(field(key) + " is missing: an array of " + std::to_string(length) +
                     " numbers is required");
  }
  if (!v->is_array() || v->size() != length)
    throw InputError(field(key) + " = " + shown(*v) + ": must be an array of " +
                     std::to_string(length) + " numbers");
  std::vector<double> out;
  for (std::size_t i = 0; i < length; ++i) {
    const auto& e = (*v)[i];
    const std::string name = field(key) + "[" + std::to_string(i) + "]";
    if (!e.is_number())
      throw InputError(name + " = " + shown(e) + ": must be a number " + range.describe());
    const double x = e.get<double>();
    if (!range.contains(x))
      throw InputError(name + " = " + exact_number(x) + ": must be " + range.describe());
    out.push_back(x);
  }
  return out;
}

InputReader InputReader::object(const std::string& key, bool required) {
  const nlohmann::json* v = find(key);
  if (!v) {
    if (required) throw InputError(field(key) + " is missing: an object is required");
    return InputReader(nlohmann::json::object(), field(key));
  }
  if (!v->is_object()) throw InputError(field(key) + " = " + shown(*v) + ": must be a JSON object");
  return InputReader(*v, field(key));
}

void InputReader::finish() const {
  for (auto it = object_.begin(); it != object_.end(); ++it) {
    if (std::find(known_.begin(), known_.end(), it.key()) != known_.end()) continue;
    std::vector<std::string> sorted = known_;
    std::sort(sorted.begin(), sorted.end());
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    std::string list;
    for (std::size_t i = 0; i < sorted.size(); ++i) list += (i ? ", " : "") + sorted[i];
    const std::string near = nearest_name(it.key(), sorted);
    throw InputError(field(it.key()) + ": unknown key" +
                     (near.empty() ? std::string() : "; did you mean " + field(near) + "?") +
                     " (known keys here: " + list + ")");
  }
}

namespace {

// The SAX pass of check_json_text: follows the path of the value being read
// (for messages) and stops at the first problem, which it keeps in `error`.
class JsonChecker {
 public:
  explicit JsonChecker(const std::string& text) : text_(text) {}
  std::string error;

  bool null() { return value(); }
  bool boolean(bool) { return value(); }
  bool number_integer(std::int64_t) { return value(); }
  bool number_unsigned(std::uint64_t) { return value(); }
  bool number_float(double, const std::string&) { return value(); }
  bool string(std::string&) { return value(); }
  bool binary(nlohmann::json::binary_t&) { return value(); }
  bool start_object(std::size_t) { return open(true); }
  bool start_array(std::size_t) { return open(false); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }
  bool key(std::string& k) {
    Frame& f = frames_.back();
    f.key = k;
    f.has_key = true;
    if (!f.keys.insert(k).second) {
      error = path() +
              ": key given twice in one object (a JSON reader would silently keep one "
              "of the two values); remove one";
      return false;
    }
    return true;
  }
  bool parse_error(std::size_t position, const std::string& token,
                   const nlohmann::detail::exception& e) {
    const std::string where = frames_.empty() ? std::string() : " (in " + path() + ")";
    if (e.id == 406)  // out_of_range.406: a number beyond double
      error = (frames_.empty() ? std::string("value") : path()) + " = " + token.substr(0, 40) +
              ": a number beyond the range of double (line " + std::to_string(line_of(position)) +
              ")";
    else
      error = std::string("not valid JSON: ") + without_prefix(e.what()) + where;
    return false;
  }

 private:
  struct Frame {
    bool object = false;
    bool has_key = false;
    std::string key;
    std::set<std::string> keys;
    std::size_t count = 0;  // elements completed (arrays)
  };

  bool value() {
    if (!frames_.empty() && !frames_.back().object) ++frames_.back().count;
    return true;
  }
  bool open(bool object) {
    if (static_cast<int>(frames_.size()) >= kMaxInputDepth) {
      error = (frames_.empty() ? std::string("document") : path()) + ": nested deeper than " +
              std::to_string(kMaxInputDepth) + " levels; case and sweep files need about five";
      return false;
    }
    frames_.push_back({object, false, {}, {}, 0});
    return true;
  }
  bool close() {
    frames_.pop_back();
    return value();
  }
  std::string path() const {
    std::string p;
    for (const Frame& f : frames_) {
      if (f.object) {
        if (f.has_key) p += (p.empty() ? "" : ".") + f.key;
      } else {
        p += "[" + std::to_string(f.count) + "]";
      }
    }
    if (p.empty()) return "top level";
    // a path into deep nesting is cut: its start says where it is
    return p.size() > 80 ? p.substr(0, 80) + "..." : p;
  }
  std::size_t line_of(std::size_t position) const {
    const std::size_t end = std::min(position, text_.size());
    return 1 + static_cast<std::size_t>(std::count(text_.begin(), text_.begin() + end, '\n'));
  }
  static std::string without_prefix(const std::string& what) {
    // "[json.exception.parse_error.101] parse error at ..." -> "parse error at ..."
    const auto close = what.find("] ");
    return what.rfind("[json.exception.", 0) == 0 && close != std::string::npos
               ? what.substr(close + 2)
               : what;
  }

  const std::string& text_;
  std::vector<Frame> frames_;
};

}  // namespace

std::string read_input_text(const std::string& filename) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(filename, ec);
  if (ec || !fs::exists(st)) throw InputError(filename + ": cannot be opened: no such file");
  if (fs::is_directory(st)) throw InputError(filename + ": is a directory, not a JSON file");
  // a FIFO would block the reader and a device never end: only plain files
  if (!fs::is_regular_file(st))
    throw InputError(filename +
                     ": not a regular file (a pipe, device or socket); give a JSON file");
  const std::uintmax_t bytes = fs::file_size(filename, ec);
  if (!ec && bytes > kMaxInputFileBytes)
    throw InputError(filename + ": " + std::to_string(bytes) + " bytes; input files are at most " +
                     std::to_string(kMaxInputFileBytes >> 20) +
                     " MiB (a case or sweep is a few kB; sphere positions belong in a "
                     "snapshot given by positions_from)");
  std::ifstream in(filename, std::ios::binary);
  if (!in) throw InputError(filename + ": cannot open file (" + std::strerror(errno) + ")");
  std::string text;
  // read one byte past the limit so that a file that grew meanwhile is still refused
  text.resize(static_cast<std::size_t>(kMaxInputFileBytes) + 1);
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (in.bad()) throw InputError(filename + ": cannot read file");
  if (text.size() > kMaxInputFileBytes)
    throw InputError(filename + ": larger than " + std::to_string(kMaxInputFileBytes >> 20) +
                     " MiB; input files are small");
  return text;
}

void check_json_text(const std::string& text, const std::string& origin) {
  // the JSON reader takes a NUL byte for the end of its input, so whatever
  // follows one was never read (`{...}\0junk` passed); JSON text holds none
  if (const auto nul = text.find('\0'); nul != std::string::npos)
    throw InputError(origin + ": a NUL byte at offset " + std::to_string(nul) +
                     ", which JSON text never holds (a binary file, or one cut and pasted?)");
  JsonChecker checker(text);
  if (!nlohmann::json::sax_parse(text, &checker)) {
    if (checker.error.empty()) checker.error = "not valid JSON";
    throw InputError(origin + ": " + checker.error);
  }
}

nlohmann::json read_json_file(const std::string& filename) {
  const std::string text = read_input_text(filename);
  check_json_text(text, filename);
  return nlohmann::json::parse(text);
}

bool whole_number(const nlohmann::json& value, long& out) {
  if (value.is_number_integer()) {
    if (value.is_number_unsigned() &&
        value.get<unsigned long>() > static_cast<unsigned long>(LONG_MAX))
      return false;
    out = value.get<long>();
    return true;
  }
  if (!value.is_number_float()) return false;
  const double x = value.get<double>();
  if (!std::isfinite(x) || x != std::floor(x) || std::fabs(x) > 9007199254740992.0) return false;
  out = static_cast<long>(x);
  return true;
}

std::string shown(const nlohmann::json& value, std::size_t limit) {
  const std::string text = value.dump();
  if (text.size() <= limit) return text;
  return text.substr(0, limit) + "... (" + std::to_string(text.size()) + " characters)";
}

}  // namespace flocsim::input
