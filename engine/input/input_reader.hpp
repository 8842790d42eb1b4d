#pragma once
// Reading JSON input (case files, sweep files) with the checks a user needs:
// every error names the field (its full path, e.g. "fluid.viscosity"), the
// value found and what is allowed; unknown keys are refused with the list of
// known ones; nothing is silently clamped or defaulted past a wrong type.
//
//   InputReader in(json, "case");
//   double nu = in.number("viscosity", {.above = 0, .at_most = 1}, 0.01);
//   in.finish();   // throws if the object had keys nobody asked for
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

// Reads a JSON file; parse errors become InputErrors naming file and position.
nlohmann::json read_json_file(const std::string& filename);

}  // namespace flocsim::input
