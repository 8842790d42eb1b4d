#include "engine/input/input_reader.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <fstream>
#include <sstream>

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
    throw InputError((path_.empty() ? std::string("input") : path_) + " = " + object_.dump() +
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
    throw InputError(field(key) + " = " + v->dump() + ": must be a number " + range.describe());
  const double x = v->get<double>();
  if (!range.contains(x))
    throw InputError(field(key) + " = " + format_number(x) + ": must be " + range.describe());
  return x;
}

long InputReader::integer(const std::string& key, const Range& range,
                          std::optional<long> fallback) {
  const nlohmann::json* v = find(key);
  if (!v) {
    if (fallback) return *fallback;
    throw InputError(field(key) + " is missing: an integer " + range.describe() + " is required");
  }
  if (!v->is_number_integer())
    throw InputError(field(key) + " = " + v->dump() + ": must be an integer " + range.describe());
  // an unsigned value beyond the range of long would wrap: refuse it
  if (v->is_number_unsigned() && v->get<unsigned long>() > static_cast<unsigned long>(LONG_MAX))
    throw InputError(field(key) + " = " + v->dump() + ": must be " + range.describe());
  const long x = v->get<long>();
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
    throw InputError(field(key) + " = " + v->dump() + ": must be true or false");
  return v->get<bool>();
}

std::string InputReader::text(const std::string& key, std::optional<std::string> fallback) {
  const nlohmann::json* v = find(key);
  if (!v) {
    if (fallback) return *fallback;
    throw InputError(field(key) + " is missing: a string is required");
  }
  if (!v->is_string()) throw InputError(field(key) + " = " + v->dump() + ": must be a string");
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
    throw InputError(field(key) + " = " + v->dump() + ": must be one of " + list);
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
    throw InputError(field(key) + " = " + v->dump() + ": must be an array of " +
                     std::to_string(length) + " numbers");
  std::vector<double> out;
  for (std::size_t i = 0; i < length; ++i) {
    const auto& e = (*v)[i];
    const std::string name = field(key) + "[" + std::to_string(i) + "]";
    if (!e.is_number())
      throw InputError(name + " = " + e.dump() + ": must be a number " + range.describe());
    const double x = e.get<double>();
    if (!range.contains(x))
      throw InputError(name + " = " + format_number(x) + ": must be " + range.describe());
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
  if (!v->is_object()) throw InputError(field(key) + " = " + v->dump() + ": must be a JSON object");
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
    throw InputError(field(it.key()) + ": unknown key (known keys here: " + list + ")");
  }
}

nlohmann::json read_json_file(const std::string& filename) {
  std::ifstream in(filename);
  if (!in) throw InputError(filename + ": cannot open file");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(filename + ": not valid JSON: " + e.what());
  }
}

}  // namespace flocsim::input
