#include "kirchhoff/jobs/detail/toml_nesting.hpp"

#include <algorithm>
#include <vector>

namespace kirchhoff {

int toml_line_beyond_nesting(const std::string& text, int limit) {
  std::vector<int> open;   // for each open [ or {: the dotted-key components before it
  int components = 0;      // the sum of `open`
  // Dots since the last ',', bracket or line end: the parts of a dotted key, carried over its '='
  // to the bracket that may open its value (a.b = { c.d = [1] } nests 1 + 1 + 1 + 1 deep). A
  // number's decimal point counts too; that only overestimates.
  int dots = 0;
  int line = 1;
  const std::size_t n = text.size();
  std::size_t i = 0;
  auto run_of = [&](char c) {  // how many c start at i
    std::size_t k = 0;
    while (i + k < n && text[i + k] == c) ++k;
    return k;
  };
  auto too_deep = [&] { return static_cast<int>(open.size()) + components + dots > limit; };
  while (i < n) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      dots = 0;
      ++i;
    } else if (c == '#') {
      while (i < n && text[i] != '\n') ++i;
    } else if (c == '"' || c == '\'') {
      // """ and ''' open multi-line strings; "" is an empty string.
      const bool multi = run_of(c) >= 3;
      i += multi ? 3 : 1;
      while (i < n) {
        if (c == '"' && text[i] == '\\') {  // an escape; in a multi-line string \ may end a line
          if (i + 1 < n && text[i + 1] == '\n') ++line;
          i += 2;
        } else if (text[i] == '\n') {
          if (!multi) break;  // a one-line string ends here (a syntax error toml11 reports)
          ++line;
          ++i;
        } else if (text[i] == c && (!multi || run_of(c) >= 3)) {
          // A multi-line string ends at the last three of a run of up to five quotes.
          i += multi ? std::min<std::size_t>(run_of(c), 5) : 1;
          break;
        } else {
          ++i;
        }
      }
    } else if (c == '[' || c == '{') {
      open.push_back(dots);
      components += dots;
      dots = 0;
      if (too_deep()) return line;
      ++i;
    } else if (c == ']' || c == '}') {
      if (!open.empty()) {
        components -= open.back();
        open.pop_back();
      }
      dots = 0;
      ++i;
    } else {
      if (c == ',') dots = 0;
      if (c == '.' && (++dots, too_deep())) return line;
      ++i;
    }
  }
  return 0;
}

std::size_t toml_invalid_utf8_at(const std::string& text) {
  const std::size_t n = text.size();
  auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  auto continuation = [&](std::size_t k, unsigned char low = 0x80, unsigned char high = 0xBF) {
    return k < n && byte(k) >= low && byte(k) <= high;
  };
  std::size_t i = 0;
  while (i < n) {
    const unsigned char b = byte(i);
    std::size_t length = 0;
    if (b <= 0x7F) {
      length = 1;
    } else if (b >= 0xC2 && b <= 0xDF) {
      length = continuation(i + 1) ? 2 : 0;
    } else if (b >= 0xE0 && b <= 0xEF) {
      // E0: no overlong forms (A0..BF next); ED: no surrogates (80..9F next).
      const unsigned char low = b == 0xE0 ? 0xA0 : 0x80, high = b == 0xED ? 0x9F : 0xBF;
      length = continuation(i + 1, low, high) && continuation(i + 2) ? 3 : 0;
    } else if (b >= 0xF0 && b <= 0xF4) {
      // F0: no overlong forms (90..BF next); F4: nothing above U+10FFFF (80..8F next).
      const unsigned char low = b == 0xF0 ? 0x90 : 0x80, high = b == 0xF4 ? 0x8F : 0xBF;
      length = continuation(i + 1, low, high) && continuation(i + 2) && continuation(i + 3) ? 4 : 0;
    }
    if (length == 0) return i;
    i += length;
  }
  return n;
}

}  // namespace kirchhoff
