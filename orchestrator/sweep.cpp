#include "orchestrator/sweep.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "engine/input/field_table.hpp"
#include "engine/input/input_reader.hpp"
#include "orchestrator/plan.hpp"
#include "orchestrator/sweep_fields.hpp"
#include "orchestrator/terminal_table.hpp"

namespace flocsim::orchestrator {

using flocsim::input::InputError;
using nlohmann::json;

json canonical(const json& value) {
  switch (value.type()) {
    case json::value_t::object: {
      json out = json::object();
      for (auto it = value.begin(); it != value.end(); ++it) out[it.key()] = canonical(it.value());
      return out;
    }
    case json::value_t::array: {
      json out = json::array();
      for (const json& v : value) out.push_back(canonical(v));
      return out;
    }
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float: {
      const double d = value.get<double>();
      constexpr double kExactIntegers = 9007199254740992.0;  // 2^53
      if (value.is_number_integer() && !value.is_number_float()) {
        // Integers beyond 2^53 stay exact integers.
        if (std::fabs(d) >= kExactIntegers) return value;
      }
      if (std::nearbyint(d) == d && std::fabs(d) < kExactIntegers)
        return json(static_cast<std::int64_t>(d));
      return json(d);
    }
    default:
      return value;
  }
}

std::string canonical_text(const json& value) {
  return canonical(value).dump();
}

namespace {

// SHA-256 (FIPS 180-4).
struct Sha256 {
  std::array<std::uint32_t, 8> h{0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                                 0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  static constexpr std::array<std::uint32_t, 64> k{
      0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4,
      0xab1c5ed5, 0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe,
      0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f,
      0x4a7484aa, 0x5cb0a9dc, 0x76f988da, 0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7,
      0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc,
      0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b,
      0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070, 0x19a4c116,
      0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
      0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7,
      0xc67178f2};
  static std::uint32_t rotr(std::uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }

  void block(const unsigned char* p) {
    std::array<std::uint32_t, 64> w{};
    for (int i = 0; i < 16; ++i)
      w[i] = (std::uint32_t(p[4 * i]) << 24) | (std::uint32_t(p[4 * i + 1]) << 16) |
             (std::uint32_t(p[4 * i + 2]) << 8) | std::uint32_t(p[4 * i + 3]);
    for (int i = 16; i < 64; ++i) {
      const std::uint32_t s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
      const std::uint32_t s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
      w[i] = w[i - 16] + s0 + w[i - 7] + s1;
    }
    std::uint32_t a = h[0], b = h[1], c = h[2], d = h[3], e = h[4], f = h[5], g = h[6], hh = h[7];
    for (int i = 0; i < 64; ++i) {
      const std::uint32_t S1 = rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25);
      const std::uint32_t ch = (e & f) ^ (~e & g);
      const std::uint32_t t1 = hh + S1 + ch + k[i] + w[i];
      const std::uint32_t S0 = rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22);
      const std::uint32_t maj = (a & b) ^ (a & c) ^ (b & c);
      const std::uint32_t t2 = S0 + maj;
      hh = g;
      g = f;
      f = e;
      e = d + t1;
      d = c;
      c = b;
      b = a;
      a = t1 + t2;
    }
    h[0] += a, h[1] += b, h[2] += c, h[3] += d, h[4] += e, h[5] += f, h[6] += g, h[7] += hh;
  }
};

}  // namespace

std::string sha256_hex(std::string_view bytes) {
  Sha256 s;
  std::string data(bytes);
  const std::uint64_t bits = static_cast<std::uint64_t>(bytes.size()) * 8;
  data.push_back(static_cast<char>(0x80));
  while (data.size() % 64 != 56) data.push_back('\0');
  for (int i = 7; i >= 0; --i) data.push_back(static_cast<char>((bits >> (8 * i)) & 0xff));
  for (std::size_t off = 0; off < data.size(); off += 64)
    s.block(reinterpret_cast<const unsigned char*>(data.data() + off));
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (std::uint32_t word : s.h)
    for (int i = 7; i >= 0; --i) out.push_back(hex[(word >> (4 * i)) & 0xf]);
  return out;
}

std::string case_id(const json& case_json) {
  return sha256_hex(canonical_text(case_json));
}

namespace {

std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> parts;
  std::string cur;
  for (char ch : path) {
    if (ch == '.') {
      parts.push_back(cur);
      cur.clear();
    } else {
      cur.push_back(ch);
    }
  }
  parts.push_back(cur);
  return parts;
}

void set_path(json& object, const std::string& path, const json& value, const std::string& where) {
  const std::vector<std::string> parts = split_path(path);
  json* node = &object;
  std::string walked;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (node->is_null()) *node = json::object();  // a path new to the base case
    if (!node->is_object())
      throw InputError(where + ": axis \"" + path + "\" goes through base." + walked + " = " +
                       node->dump() + ", which is not an object");
    walked += (i ? "." : "") + parts[i];
    node = &(*node)[parts[i]];
  }
  *node = value;
}

std::string describe(const json& v) {
  std::string s = v.dump();
  return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

}  // namespace

std::optional<json> get_path(const json& object, const std::string& path) {
  const json* node = &object;
  for (const std::string& part : split_path(path)) {
    if (!node->is_object()) return std::nullopt;
    auto it = node->find(part);
    if (it == node->end()) return std::nullopt;
    node = &*it;
  }
  return *node;
}

namespace {
// A sweep field's range and default, from its declaration (sweep_fields.cpp).
const flocsim::input::FieldSpec& sweep_field(const std::string& path) {
  const flocsim::input::FieldSpec* f = sweep_field_table().find(path);
  if (!f) throw std::logic_error("sweep field " + path + " is not declared");
  return *f;
}
const flocsim::input::Range& range_of(const std::string& path) {
  return sweep_field(path).range;
}
long fallback_integer(const std::string& path) {
  return sweep_field(path).fallback.get<long>();
}
std::string fallback_text(const std::string& path) {
  return sweep_field(path).fallback.get<std::string>();
}
// The axes: each a dotted case path with a non-empty array of distinct
// scalars; none inside another; at most kMaxRunsPerSweep points in all.
void read_axes(const nlohmann::ordered_json& file, const std::string& where, SweepSpec& s) {
  std::size_t total = 1;
  for (auto it = file["axes"].begin(); it != file["axes"].end(); ++it) {
    const std::string& path = it.key();
    const std::string field = "axes." + path;
    for (const std::string& part : split_path(path))
      if (part.empty())
        throw InputError(where + ": axis \"" + path +
                         "\" is not a dotted path of case fields (empty segment)");
    if (!it.value().is_array() || it.value().empty())
      throw InputError(where + ": " + field + " = " + describe(json(it.value())) +
                       ": must be a non-empty array of values");
    Axis axis{path, {}};
    std::set<std::string> seen;
    for (const auto& v : it.value()) {
      const json value(v);
      if (!(value.is_number() || value.is_string() || value.is_boolean()))
        throw InputError(where + ": " + field + " holds " + describe(value) +
                         ": axis values must be numbers, strings or booleans");
      if (!seen.insert(canonical_text(value)).second)
        throw InputError(where + ": " + field + " lists " + describe(canonical(value)) + " twice");
      axis.values.push_back(value);
    }
    if (s.fidelity && path == "fidelity")
      throw InputError(where + ": fidelity is both a top-level preset and an axis; use one");
    total *= axis.values.size();
    if (total > kMaxRunsPerSweep)
      throw InputError(where + ": the grid has more than " + std::to_string(kMaxRunsPerSweep) +
                       " runs; split it into several sweeps");
    s.axes.push_back(std::move(axis));
  }
  for (std::size_t i = 0; i < s.axes.size(); ++i)
    for (std::size_t j = 0; j < i; ++j) {
      const std::string& a = s.axes[j].path;
      const std::string& b = s.axes[i].path;
      if (b.rfind(a + ".", 0) == 0 || a.rfind(b + ".", 0) == 0)
        throw InputError(where + ": axes \"" + a + "\" and \"" + b +
                         "\" overlap (one lies inside the other)");
    }
}

}  // namespace

SweepSpec parse_sweep(const nlohmann::ordered_json& file, const std::string& origin) {
  const std::string where = "sweep file " + origin;
  if (!file.is_object())
    throw InputError(where + ": must hold a JSON object, found " + describe(json(file)));
  SweepSpec s;
  s.source = json(file);
  try {
    // every field against its declaration (sweep_fields.cpp): unknown keys
    // with the nearest known one, types, ranges, Slurm's one-word syntax
    flocsim::input::check_fields(sweep_field_table(), s.source, -1);
    flocsim::input::InputReader in(s.source, "");
    s.name = in.text("name");
    if (s.name.empty() || s.name.find_first_of(" \t\n\r\v\f/\\") != std::string::npos)
      throw InputError("name = \"" + s.name +
                       "\": must be a non-empty word without spaces or slashes");
    s.description = in.text("description", fallback_text("description"));
    s.max_attempts = static_cast<int>(
        in.integer("max_attempts", range_of("max_attempts"), fallback_integer("max_attempts")));
    if (in.has("fidelity")) s.fidelity = in.text("fidelity");
    in.object("base", true);  // checked to be an object; contents are the worker's business
    in.object("axes", true);
    flocsim::input::InputReader slurm = in.object("slurm");
    s.slurm.runs_per_task = static_cast<int>(slurm.integer(
        "runs_per_task", range_of("slurm.runs_per_task"), fallback_integer("slurm.runs_per_task")));
    s.slurm.time_limit = slurm.text("time_limit", fallback_text("slurm.time_limit"));
    s.slurm.partition = slurm.text("partition", fallback_text("slurm.partition"));
    s.slurm.gres = slurm.text("gres", fallback_text("slurm.gres"));
    // both go into the job script's #SBATCH lines: one word each, so that no
    // value can end a line and start a shell command there
    for (const auto& [field, value] :
         {std::pair<std::string, std::string>{"slurm.time_limit", s.slurm.time_limit},
          {"slurm.partition", s.slurm.partition},
          {"slurm.gres", s.slurm.gres}})
      if (value.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                  "0123456789:-_.,") != std::string::npos)
        throw InputError(field + " = " + flocsim::input::shown(value) +
                         ": must be one word of letters, digits and : - _ . , (Slurm's syntax)");
    // read here, when the sweep is read: "abc" went to sbatch after the sweep
    // was registered, twenty digits stopped the plan with "error: stol"
    if (!slurm_time_limit_s(s.slurm.time_limit) && s.slurm.time_limit != "UNLIMITED" &&
        s.slurm.time_limit != "INFINITE")
      throw InputError("slurm.time_limit = " + flocsim::input::shown(s.slurm.time_limit) +
                       ": not a Slurm time limit; allowed: MINUTES, MINUTES:SECONDS, "
                       "HOURS:MINUTES:SECONDS, DAYS-HOURS, DAYS-HOURS:MINUTES, "
                       "DAYS-HOURS:MINUTES:SECONDS (numbers of at most 9 digits) or UNLIMITED");
    s.slurm.max_parallel = static_cast<int>(slurm.integer(
        "max_parallel", range_of("slurm.max_parallel"), fallback_integer("slurm.max_parallel")));
    s.slurm.cpus_per_task = static_cast<int>(slurm.integer(
        "cpus_per_task", range_of("slurm.cpus_per_task"), fallback_integer("slurm.cpus_per_task")));
    slurm.finish();
    in.finish();
  } catch (const InputError& e) {
    throw InputError(where + ": " + e.what());
  }
  s.base = s.source["base"];
  if (s.fidelity) {
    if (s.base.contains("fidelity"))
      throw InputError(where + ": fidelity is given both at the top level (\"" + *s.fidelity +
                       "\") and in base.fidelity (" + describe(s.base["fidelity"]) +
                       "); give it once");
    s.base["fidelity"] = *s.fidelity;
  }
  read_axes(file, where, s);
  return s;
}

SweepSpec read_sweep_file(const std::string& filename) {
  std::string text;
  try {
    text = flocsim::input::read_input_text(filename);
  } catch (const InputError& e) {
    throw InputError(std::string("sweep file ") + e.what());
  }
  flocsim::input::check_json_text(text, "sweep file " + filename);
  nlohmann::ordered_json file = nlohmann::ordered_json::parse(text);
  // A relative positions_from names a file beside the sweep file, not in
  // whatever folder the sweep is launched (or resumed, or run by Slurm) from:
  // it is made absolute here, so that the stored case names one file.
  const std::filesystem::path folder = std::filesystem::absolute(filename).parent_path();
  auto anchor = [&folder](nlohmann::ordered_json& v) {
    if (!v.is_string() || v.get<std::string>().empty()) return;
    const std::filesystem::path p(v.get<std::string>());
    if (p.is_relative()) v = (folder / p).lexically_normal().string();
  };
  if (file.is_object() && file.contains("base") && file["base"].is_object() &&
      file["base"].contains("positions_from"))
    anchor(file["base"]["positions_from"]);
  if (file.is_object() && file.contains("axes") && file["axes"].is_object() &&
      file["axes"].contains("positions_from") && file["axes"]["positions_from"].is_array())
    for (auto& v : file["axes"]["positions_from"]) anchor(v);
  return parse_sweep(file, filename);
}

std::vector<RunPoint> expand(const SweepSpec& sweep) {
  std::vector<RunPoint> out;
  std::vector<std::size_t> index(sweep.axes.size(), 0);
  std::set<std::string> ids;
  while (true) {
    RunPoint p;
    json c = sweep.base;
    p.point = nlohmann::ordered_json::object();
    for (std::size_t a = 0; a < sweep.axes.size(); ++a) {
      const json& v = sweep.axes[a].values[index[a]];
      set_path(c, sweep.axes[a].path, v, "sweep " + sweep.name);
      p.point[sweep.axes[a].path] = canonical(v);
    }
    p.case_json = canonical(c);
    p.id = case_id(p.case_json);
    if (!ids.insert(p.id).second)
      throw InputError("sweep " + sweep.name + ": two grid points give the same case (" +
                       p.point.dump() + "); remove the duplicate axis value");
    out.push_back(std::move(p));
    // Odometer: the last axis varies fastest.
    std::size_t a = sweep.axes.size();
    while (a > 0) {
      --a;
      if (++index[a] < sweep.axes[a].values.size()) break;
      index[a] = 0;
      if (a == 0) return out;
    }
    if (sweep.axes.empty()) return out;
  }
}

std::string point_text(const std::string& point_json) {
  if (point_json.empty()) return "";
  const auto p = nlohmann::ordered_json::parse(point_json, nullptr, false);
  if (!p.is_object()) return printable(point_json);
  std::string out;
  for (auto it = p.begin(); it != p.end(); ++it)
    out += (out.empty() ? "" : " ") + it.key() + "=" +
           (it.value().is_string() ? it.value().get<std::string>() : it.value().dump());
  return printable(out);  // for terminals: a value's ESC or U+202E is shown, not obeyed
}

std::string shell_word(const std::string& word) {
  const bool plain = !word.empty() && word.find_first_not_of(
                                          "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                          "0123456789-_./:,+=@") == std::string::npos;
  if (plain) return word;
  if (!text::is_printable(word)) {
    // bash's $'...': every byte a terminal would obey (or that is not UTF-8)
    // as \xNN, so the line shows what it is and pastes back the same bytes
    static constexpr char hex[] = "0123456789abcdef";
    std::string out = "$'";
    for (std::size_t i = 0; i < word.size();) {
      const text::Utf8Char c = text::decode_utf8(word, i);
      const std::size_t n = c.length == 0 ? 1 : c.length;
      if (c.length == 0 || text::is_terminal_control(c.code_point)) {
        for (std::size_t k = 0; k < n; ++k) {
          const auto b = static_cast<unsigned char>(word[i + k]);
          out += {'\\', 'x', hex[b >> 4], hex[b & 15]};
        }
      } else if (word[i] == '\\' || word[i] == '\'') {
        out += {'\\', word[i]};
      } else {
        out.append(word, i, n);
      }
      i += n;
    }
    return out + "'";
  }
  std::string out = "'";
  for (char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace flocsim::orchestrator
