// Internal: a double written as a CSV cell, as `out << std::setprecision(15) << v` writes it
// (printf's %.15g: "nan", "-nan", "inf", "-0" included), through std::to_chars. The stream's own
// insertion formats through vsnprintf: 30,700 instructions a row of the branch CSV (3.7 % of the
// Euler column's README branch, callgrind), against a few hundred a number here.
#pragma once

#include <charconv>
#include <ostream>

namespace kirchhoff::detail {

inline constexpr int kCsvPrecision = 15;

inline void put_csv_number(std::ostream& out, double v) {
  char text[32];  // %.15g needs at most 22: sign, 15 digits, point, e-308
  const std::to_chars_result r = std::to_chars(text, text + sizeof text, v, std::chars_format::general, kCsvPrecision);
  out.write(text, r.ptr - text);
}

}  // namespace kirchhoff::detail
