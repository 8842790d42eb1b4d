#pragma once
// Reading JSON input (case files, sweep files) with the checks a user needs:
// every error names the field (its full path, e.g. "fluid.viscosity"), the
// value found and what is allowed; unknown keys are refused with the list of
// known ones; nothing is silently clamped or defaulted past a wrong type.
//
//   InputReader in(json, "case");
//   double nu = in.number("viscosity", {.above = 0, .at_most = 1}, 0.01);
//   in.finish();   // throws if the object had keys nobody asked for
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace flocsim::input {

// An input refused before any work starts.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Allowed range of a number; unset bounds are open.
struct Range {
  std::optional<double> at_least, above, at_most, below;
  std::string why;  // optional reason appended to the message, e.g. "(Mach limit)"
  std::string describe() const;
  bool contains(double v) const;
};

class InputReader {
 public:
  InputReader(const nlohmann::json& object, std::string path);

  // Required when `fallback` is empty.
  double number(const std::string& key, const Range& range,
                std::optional<double> fallback = std::nullopt);
  long integer(const std::string& key, const Range& range,
               std::optional<long> fallback = std::nullopt);
  bool boolean(const std::string& key, std::optional<bool> fallback = std::nullopt);
  std::string text(const std::string& key, std::optional<std::string> fallback = std::nullopt);
  std::string choice(const std::string& key, const std::vector<std::string>& allowed,
                     std::optional<std::string> fallback = std::nullopt);
  // A fixed-length array of numbers, each in range.
  std::vector<double> numbers(const std::string& key, std::size_t length, const Range& range,
                              std::optional<std::vector<double>> fallback = std::nullopt);
  // A nested object (empty object when absent and optional).
  InputReader object(const std::string& key, bool required = false);
  bool has(const std::string& key) const;

  // Throws InputError when the object holds keys that were never read.
  void finish() const;

  const std::string& path() const { return path_; }
  std::string field(const std::string& key) const {
    return path_.empty() ? key : path_ + "." + key;
  }

 private:
  const nlohmann::json* find(const std::string& key);
  nlohmann::json object_;
  std::string path_;
  std::vector<std::string> known_;
};

// Input files are small (a case or a sweep is a few kB; sphere positions come
// from HDF5 snapshots, not JSON): anything larger is refused before it is read.
inline constexpr std::uintmax_t kMaxInputFileBytes = 4u << 20;
// Case and sweep files nest four or five levels; the limit keeps every later
// recursive walk of the document (copy, dump, destruction) far from the stack's end.
inline constexpr int kMaxInputDepth = 64;

// The text of an input file, refused with an InputError naming the file when
// it is missing, a directory, unreadable or larger than kMaxInputFileBytes.
std::string read_input_text(const std::string& filename);

// Checks JSON text without building a document (an iterative SAX pass, so
// that no input can exhaust the stack) and throws an InputError naming
// `origin`, the field's path and the line for: a syntax error, a number
// beyond the range of double, nesting deeper than kMaxInputDepth, or a key
// given twice in one object (JSON parsers would silently keep the last).
void check_json_text(const std::string& text, const std::string& origin);

// Reads a JSON file through read_input_text and check_json_text.
nlohmann::json read_json_file(const std::string& filename);

// A JSON value as shown in a message: its text, cut to `limit` characters.
std::string shown(const nlohmann::json& value, std::size_t limit = 80);

// A whole number as JSON may write it: 2000, or 2000.0 and 2e3, which JSON
// readers store as floating point (a sweep axis takes them as one number);
// false for a fraction, a value beyond long, or one past 2^53, where a
// double no longer holds every whole number exactly.
bool whole_number(const nlohmann::json& value, long& out);

}  // namespace flocsim::input
