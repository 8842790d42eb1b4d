#include "engine/input/field_table.hpp"

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <regex>
#include <sstream>

namespace flocsim::input {

namespace {

std::string parent_of(const std::string& path) {
  const auto dot = path.rfind('.');
  return dot == std::string::npos ? std::string() : path.substr(0, dot);
}

std::string leaf_of(const std::string& path) {
  const auto dot = path.rfind('.');
  return dot == std::string::npos ? path : path.substr(dot + 1);
}

std::string joined(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

bool applies(const FieldSpec& f, int context) {
  return context < 0 || (f.contexts >> context) & 1u;
}

std::string choices_text(const FieldSpec& f) {
  std::string list;
  for (std::size_t i = 0; i < f.choices.size(); ++i)
    list += (i ? ", " : "") + ("\"" + f.choices[i] + "\"");
  return list;
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                        std::tolower(static_cast<unsigned char>(b[j - 1]));
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The type and range checks of one given value.
void check_value(const FieldSpec& f, const nlohmann::json& v) {
  const std::string& p = f.path;
  switch (f.type) {
    case FieldType::number:
      if (!v.is_number())
        throw InputError(p + " = " + shown(v) + ": must be a number " + f.range.describe());
      if (!f.range.contains(v.get<double>()))
        throw InputError(p + " = " + exact_number(v.get<double>()) + ": must be " +
                         f.range.describe());
      return;
    case FieldType::integer: {
      long x = 0;
      if (v.is_number() && !f.range.contains(v.get<double>()))
        throw InputError(p + " = " + shown(v) + ": must be " + f.range.describe());
      if (!whole_number(v, x))
        throw InputError(p + " = " + shown(v) + ": must be a whole number " + f.range.describe());
      if (!f.range.contains(static_cast<double>(x)))
        throw InputError(p + " = " + shown(v) + ": must be " + f.range.describe());
      return;
    }
    case FieldType::boolean:
      if (!v.is_boolean()) throw InputError(p + " = " + shown(v) + ": must be true or false");
      return;
    case FieldType::string:
      if (!v.is_string()) throw InputError(p + " = " + shown(v) + ": must be a string");
      if (!f.pattern.empty() &&
          !std::regex_match(v.get<std::string>(), std::regex(f.pattern, std::regex::ECMAScript)))
        throw InputError(p + " = " + shown(v) + ": must be " +
                         (f.range.why.empty() ? "a string matching " + f.pattern : f.range.why));
      return;
    case FieldType::choice:
      if (!v.is_string() ||
          std::find(f.choices.begin(), f.choices.end(), v.get<std::string>()) == f.choices.end())
        throw InputError(p + " = " + shown(v) + ": must be one of " + choices_text(f));
      return;
    case FieldType::numbers:
      if (!v.is_array() || v.size() != f.length)
        throw InputError(p + " = " + shown(v) + ": must be an array of " +
                         std::to_string(f.length) + " numbers");
      for (std::size_t i = 0; i < v.size(); ++i) {
        const std::string name = p + "[" + std::to_string(i) + "]";
        if (!v[i].is_number())
          throw InputError(name + " = " + shown(v[i]) + ": must be a number " + f.range.describe());
        if (!f.range.contains(v[i].get<double>()))
          throw InputError(name + " = " + exact_number(v[i].get<double>()) + ": must be " +
                           f.range.describe());
      }
      return;
    case FieldType::object:
      if (!v.is_object()) throw InputError(p + " = " + shown(v) + ": must be a JSON object");
      return;
  }
}

// The first field given inside `value` at `path` (itself when not a
// non-empty object), with its value.
std::pair<std::string, nlohmann::json> first_leaf(std::string path, nlohmann::json value) {
  while (value.is_object() && !value.empty()) {
    path += "." + value.begin().key();
    value = nlohmann::json(value.begin().value());
  }
  return {path, value};
}

void walk(const FieldTable& table, const nlohmann::json& object, const std::string& parent,
          int context, bool quiet, std::vector<std::string>& warnings) {
  const std::string context_name =
      context >= 0 && static_cast<std::size_t>(context) < table.context_names.size()
          ? table.context_names[static_cast<std::size_t>(context)]
          : std::string();
  for (const FieldSpec& f : table.fields) {
    if (parent_of(f.path) != parent) continue;
    const auto it = object.find(leaf_of(f.path));
    if (it == object.end()) continue;
    bool quiet_below = quiet;
    // inside an object already warned about as unused, its fields are only checked
    if (!applies(f, context) && !quiet) {
      // a refused object is named by the first field given in it ("run.steps =
      // 10"), so that the message names the field the user wrote
      const auto [path, value] = first_leaf(f.path, *it);
      if (!f.warn_when_unused)
        throw InputError(path + " = " + shown(value, 40) + ": only for " + table.context_field +
                         " " + table.contexts_text(f) + " (" + table.context_field + " = \"" +
                         context_name + "\"" + (f.unused.empty() ? "" : ", which " + f.unused) +
                         ")");
      warnings.push_back(f.path + ": " + table.context_field + " \"" + context_name + "\" " +
                         f.unused + " (given: " + shown(*it, 40) + ")");
      quiet_below = true;
    }
    check_value(f, *it);
    if (f.type == FieldType::object && !f.open)
      walk(table, *it, f.path, context, quiet_below, warnings);
  }
  for (auto it = object.begin(); it != object.end(); ++it) {
    const std::string path = joined(parent, it.key());
    if (table.find(path)) continue;
    const std::vector<std::string> known = table.keys_under(parent, context);
    const std::string near = nearest_name(it.key(), known);
    std::string list;
    for (std::size_t i = 0; i < known.size(); ++i) list += (i ? ", " : "") + known[i];
    throw InputError(
        path + ": unknown key" +
        (near.empty() ? std::string() : "; did you mean " + joined(parent, near) + "?") +
        " (known keys here: " + list + ")");
  }
}

std::string range_text(const Range& r) {
  // the bounds as the documentation writes them (no reason appended)
  Range bare = r;
  bare.why.clear();
  return bare.describe();
}

}  // namespace

std::string exact_number(double v) {
  if (!std::isfinite(v)) return std::isnan(v) ? "NaN" : (v > 0 ? "inf" : "-inf");
  for (int digits = 6; digits < 17; ++digits) {
    std::ostringstream s;
    s.precision(digits);
    s << v;
    if (std::stod(s.str()) == v) return s.str();
  }
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

const FieldSpec* FieldTable::find(std::string_view path) const {
  for (const FieldSpec& f : fields)
    if (f.path == path) return &f;
  return nullptr;
}

std::vector<std::string> FieldTable::keys_under(const std::string& parent, int context) const {
  std::vector<std::string> keys;
  for (const FieldSpec& f : fields)
    if (parent_of(f.path) == parent && applies(f, context)) keys.push_back(leaf_of(f.path));
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

std::string FieldTable::contexts_text(const FieldSpec& f) const {
  std::string out;
  for (std::size_t i = 0; i < context_names.size(); ++i)
    if ((f.contexts >> i) & 1u) out += (out.empty() ? "\"" : ", \"") + context_names[i] + "\"";
  return out;
}

std::string nearest_name(const std::string& given, const std::vector<std::string>& known) {
  std::string best;
  std::size_t best_distance = std::string::npos;
  const std::string g = lower(given);
  for (const std::string& k : known) {
    const std::string lk = lower(k);
    std::size_t d = edit_distance(g, lk);
    // a part of a name ("spacing", "Re") is as near as a typo
    if (g.size() >= 2 && (lk.find(g) != std::string::npos || g.find(lk) != std::string::npos))
      d = std::min<std::size_t>(d, 1);
    if (d < best_distance) {
      best_distance = d;
      best = k;
    }
  }
  const std::size_t allowed = std::max<std::size_t>(2, given.size() / 3);
  return best_distance <= allowed ? best : std::string();
}

std::vector<std::string> check_fields(const FieldTable& table, const nlohmann::json& document,
                                      int context) {
  if (!document.is_object())
    throw InputError("input = " + shown(document) + ": must be a JSON object");
  std::vector<std::string> warnings;
  walk(table, document, "", context, false, warnings);
  return warnings;
}

std::string type_text(const FieldSpec& f) {
  switch (f.type) {
    case FieldType::number:
      return "number";
    case FieldType::integer:
      return "integer";
    case FieldType::boolean:
      return "boolean";
    case FieldType::string:
      return "string";
    case FieldType::choice:
      return "choice";
    case FieldType::numbers:
      return std::to_string(f.length) + " numbers";
    case FieldType::object:
      return "object";
  }
  return "";
}

std::string allowed_text(const FieldSpec& f) {
  switch (f.type) {
    case FieldType::number:
    case FieldType::integer:
      return range_text(f.range);
    case FieldType::numbers:
      return "each " + range_text(f.range);
    case FieldType::choice:
      return choices_text(f);
    case FieldType::boolean:
      return "true, false";
    case FieldType::string:
      return f.pattern.empty() ? "any string" : f.range.why;
    case FieldType::object:
      return "an object";
  }
  return "";
}

std::string default_text(const FieldSpec& f) {
  if (!f.default_rule.empty()) return f.default_rule;
  if (f.fallback.is_null()) return "-";
  if (f.fallback.is_number_float()) return exact_number(f.fallback.get<double>());
  return f.fallback.dump();
}

std::string explain(const FieldTable& table, const FieldSpec& f) {
  std::ostringstream out;
  out << f.path << " (" << type_text(f) << ")\n  " << f.doc << "\n"
      << "  allowed: " << allowed_text(f)
      << (f.range.why.empty() || f.type == FieldType::string ? "" : " " + f.range.why)
      << "\n  default: " << default_text(f) << "\n";
  if (!f.unit.empty()) out << "  unit:    " << f.unit << "\n";
  if (!table.context_names.empty()) {
    out << "  " << table.context_field << ": " << table.contexts_text(f);
    const bool everywhere =
        f.contexts == kEveryContext || (f.contexts & ((1u << table.context_names.size()) - 1)) ==
                                           (1u << table.context_names.size()) - 1;
    if (!everywhere) out << (f.warn_when_unused ? " (elsewhere: warned)" : " (elsewhere: refused)");
    out << "\n";
  }
  if (!f.rules.empty()) out << "  also:    " << f.rules << "\n";
  return out.str();
}

std::string markdown_table(const FieldTable& table, const std::vector<std::string>& sections) {
  auto cell = [](std::string s) {
    std::string out;
    for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
    return out;
  };
  auto wanted = [&](const FieldSpec& f) {
    if (sections.empty()) return true;
    for (const std::string& s : sections)
      if (f.path == s || f.path.rfind(s + ".", 0) == 0) return true;
    return false;
  };
  std::ostringstream out;
  const bool scenes = !table.context_names.empty();
  out << "| field | type | allowed | default | unit |"
      << (scenes ? " " + table.context_field + "s |" : "") << " meaning |\n|---|---|---|---|---|"
      << (scenes ? "---|" : "") << "---|\n";
  for (const FieldSpec& f : table.fields) {
    if (!wanted(f)) continue;
    std::string meaning = f.doc;
    if (!f.range.why.empty() && f.type != FieldType::string) meaning += " " + f.range.why;
    if (!f.rules.empty()) meaning += "; also: " + f.rules;
    out << "| `" << f.path << "` | " << type_text(f) << " | " << cell(allowed_text(f)) << " | "
        << cell(default_text(f)) << " | " << (f.unit.empty() ? "-" : cell(f.unit)) << " |";
    if (scenes) {
      std::string where = table.contexts_text(f);
      where.erase(std::remove(where.begin(), where.end(), '"'), where.end());
      out << " " << where << " |";
    }
    out << " " << cell(meaning) << " |\n";
  }
  return out.str();
}

nlohmann::ordered_json field_schema(const FieldTable& table, const FieldSpec& f) {
  nlohmann::ordered_json s;
  auto bounds = [](nlohmann::ordered_json& to, const Range& r) {
    if (r.at_least) to["minimum"] = *r.at_least;
    if (r.above) to["exclusiveMinimum"] = *r.above;
    if (r.at_most) to["maximum"] = *r.at_most;
    if (r.below) to["exclusiveMaximum"] = *r.below;
  };
  std::string description = f.doc;
  if (!f.unit.empty()) description += " Unit: " + f.unit + ".";
  if (!f.range.why.empty() && f.type != FieldType::string) description += " " + f.range.why;
  if (!f.default_rule.empty()) description += " Default: " + f.default_rule + ".";
  if (!f.rules.empty()) description += " Also: " + f.rules + ".";
  s["description"] = description;
  switch (f.type) {
    case FieldType::number:
    case FieldType::integer:
      s["type"] = f.type == FieldType::number ? "number" : "integer";
      bounds(s, f.range);
      break;
    case FieldType::boolean:
      s["type"] = "boolean";
      break;
    case FieldType::string:
      s["type"] = "string";
      if (!f.pattern.empty()) s["pattern"] = f.pattern;
      break;
    case FieldType::choice:
      s["type"] = "string";
      s["enum"] = f.choices;
      break;
    case FieldType::numbers: {
      s["type"] = "array";
      nlohmann::ordered_json item = {{"type", "number"}};
      bounds(item, f.range);
      s["items"] = item;
      s["minItems"] = f.length;
      s["maxItems"] = f.length;
      break;
    }
    case FieldType::object:
      s["type"] = "object";
      if (f.open) break;
      s["properties"] = schema_properties(table, f.path);
      s["additionalProperties"] = false;
      break;
  }
  if (!f.fallback.is_null()) s["default"] = f.fallback;
  return s;
}

nlohmann::ordered_json schema_properties(const FieldTable& table, const std::string& parent) {
  nlohmann::ordered_json properties = nlohmann::ordered_json::object();
  for (const FieldSpec& f : table.fields)
    if (parent_of(f.path) == parent) properties[leaf_of(f.path)] = field_schema(table, f);
  return properties;
}

}  // namespace flocsim::input
