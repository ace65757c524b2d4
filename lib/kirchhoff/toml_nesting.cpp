#include "kirchhoff/toml_nesting.hpp"

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

}  // namespace kirchhoff
