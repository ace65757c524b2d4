// libFuzzer target: the string handling in front of the case-file loader, which is cheap enough
// to fuzz for millions of executions (case_file_fuzzer spends ~90% of each execution inside
// toml11 and manages tens to hundreds per second):
//   - parse_override, the --set NAME=VALUE parser: every input is either refused with
//     std::invalid_argument or gives an identifier and the number its text after '=' spells
//     (inf and nan included: the value's range is load_case's to refuse, case_file_fuzzer's
//     target);
//   - toml_line_beyond_nesting, the scan that keeps deep nesting away from toml11's recursive
//     parser: it must end on any bytes, name a line that exists, and be monotonic in the limit.
// A violated property aborts, which libFuzzer reports with the input.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/detail/toml_nesting.hpp"

namespace {

void require(bool property) {
  if (!property) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);

  try {
    const auto [name, value] = kirchhoff::parse_override(text);
    require(!name.empty() && !std::isdigit(static_cast<unsigned char>(name[0])));
    for (const char c : name) require(std::isalnum(static_cast<unsigned char>(c)) || c == '_');
    require(text.compare(0, name.size() + 1, name + "=") == 0);
    const double spelled = std::strtod(text.c_str() + name.size() + 1, nullptr);
    require(std::isnan(value) ? std::isnan(spelled) : value == spelled);
  } catch (const std::invalid_argument&) {
    // Refused: the CLI exits 2 with the message.
  }

  const int lines = 1 + static_cast<int>(std::count(text.begin(), text.end(), '\n'));
  const int at64 = kirchhoff::toml_line_beyond_nesting(text, 64);
  const int at8 = kirchhoff::toml_line_beyond_nesting(text, 8);
  require(at64 >= 0 && at64 <= lines);
  require(at8 >= 0 && at8 <= lines);
  // Deeper than 64 is deeper than 8, and is seen no earlier.
  require(at64 == 0 || (at8 != 0 && at8 <= at64));
  return 0;
}
