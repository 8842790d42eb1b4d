#pragma once
// Text from outside (sweep files, databases, command-line words, file names,
// a worker's output) made safe to print on a terminal. Header-only and
// dependency-free, so that every printer can use the one definition: the
// orchestrator's tables and progress lines, `flocsim query`, and the error
// messages each subcommand prints on stderr.
//
// A terminal obeys some characters instead of showing them: C0 controls and
// DEL (ESC starts sequences that recolour, move, clear or retitle the screen;
// a newline or carriage return forges a line), the C1 controls U+0080-U+009F
// (U+009B is a one-character ESC [), and the bidirectional controls (U+202E
// shows "evil\u202egpj.exe" as "evilexe.jpg"). Each of these is written as an
// escape that says what it is: \x1b for C0 and DEL, \u202e for the others.
// Bytes that are not UTF-8 (a lone continuation byte, an overlong form, a
// surrogate, a sequence cut short, 0xF5-0xFF) are written as \xNN, one per
// byte; everything else, "Å", "φ" and the rest of UTF-8 included, is kept.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace flocsim::text {

// The UTF-8 sequence at `s[i]`: its code point and length, or length 0 when
// the bytes there are not a well-formed sequence (RFC 3629).
struct Utf8Char {
  std::uint32_t code_point = 0;
  std::size_t length = 0;
};

inline Utf8Char decode_utf8(std::string_view s, std::size_t i) {
  const auto at = [&](std::size_t k) -> unsigned {
    return i + k < s.size() ? static_cast<unsigned char>(s[i + k]) : 0u;
  };
  const unsigned b = at(0);
  if (b < 0x80) return {b, 1};
  const auto cont = [&](std::size_t k) { return (at(k) & 0xC0u) == 0x80u; };
  if (b >= 0xC2 && b <= 0xDF && cont(1)) return {((b & 0x1Fu) << 6) | (at(1) & 0x3Fu), 2};
  if (b >= 0xE0 && b <= 0xEF && cont(1) && cont(2)) {
    const std::uint32_t cp = ((b & 0x0Fu) << 12) | ((at(1) & 0x3Fu) << 6) | (at(2) & 0x3Fu);
    if (cp < 0x800 || (cp >= 0xD800 && cp <= 0xDFFF)) return {};  // overlong, surrogate
    return {cp, 3};
  }
  if (b >= 0xF0 && b <= 0xF4 && cont(1) && cont(2) && cont(3)) {
    const std::uint32_t cp =
        ((b & 0x07u) << 18) | ((at(1) & 0x3Fu) << 12) | ((at(2) & 0x3Fu) << 6) | (at(3) & 0x3Fu);
    if (cp < 0x10000 || cp > 0x10FFFF) return {};
    return {cp, 4};
  }
  return {};
}

// Whether a terminal obeys code point `cp` rather than showing it.
inline bool is_terminal_control(std::uint32_t cp) {
  return cp < 0x20 || cp == 0x7F || (cp >= 0x80 && cp <= 0x9F) ||  // C0, DEL, C1
         cp == 0x061C || cp == 0x200E || cp == 0x200F ||           // ALM, LRM, RLM
         (cp >= 0x202A && cp <= 0x202E) ||                         // LRE RLE PDF LRO RLO
         (cp >= 0x2066 && cp <= 0x2069) ||                         // LRI RLI FSI PDI
         cp == 0x2028 || cp == 0x2029;                             // line, paragraph separator
}

// \uXXXX for a code point of the Basic Multilingual Plane (every control
// is_terminal_control names is one).
inline void append_u_escape(std::string& out, std::uint32_t cp) {
  static constexpr char hex[] = "0123456789abcdef";
  out += {'\\', 'u', hex[(cp >> 12) & 15], hex[(cp >> 8) & 15], hex[(cp >> 4) & 15], hex[cp & 15]};
}

// `text` as a terminal should show it (see above). Only printable ASCII is
// added, so printable(printable(s)) == printable(s).
inline std::string printable(std::string_view text) {
  static constexpr char hex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const Utf8Char c = decode_utf8(text, i);
    if (c.length == 0) {  // not UTF-8: the byte as it is
      const auto b = static_cast<unsigned char>(text[i]);
      out += {'\\', 'x', hex[b >> 4], hex[b & 15]};
      i += 1;
    } else if (c.code_point < 0x80 && is_terminal_control(c.code_point)) {
      out += {'\\', 'x', hex[c.code_point >> 4], hex[c.code_point & 15]};
      i += 1;
    } else if (is_terminal_control(c.code_point)) {
      append_u_escape(out, c.code_point);
      i += c.length;
    } else {
      out.append(text.substr(i, c.length));
      i += c.length;
    }
  }
  return out;
}

// Whether printable(text) would change it.
inline bool is_printable(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    const Utf8Char c = decode_utf8(text, i);
    if (c.length == 0 || is_terminal_control(c.code_point)) return false;
    i += c.length;
  }
  return true;
}

// JSON text (as nlohmann's dump writes it: C0 controls already escaped) with
// DEL, the C1 and the bidirectional controls written as JSON's own \uXXXX
// escapes: the same document, safe on a terminal. Such characters occur in
// JSON text only inside strings, where \uXXXX stands for them exactly.
inline std::string printable_json(std::string_view json_text) {
  std::string out;
  out.reserve(json_text.size());
  for (std::size_t i = 0; i < json_text.size();) {
    const Utf8Char c = decode_utf8(json_text, i);
    const std::size_t n = c.length == 0 ? 1 : c.length;
    if (c.length != 0 && c.code_point >= 0x20 && is_terminal_control(c.code_point))
      append_u_escape(out, c.code_point);
    else
      out.append(json_text.substr(i, n));
    i += n;
  }
  return out;
}

}  // namespace flocsim::text
