#include "kirchhoff/model/detail/profile_jumps.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>

namespace kirchhoff {
namespace {

// An interval is a candidate when its change exceeds kStandsOut times the median change of the
// kWindow intervals on either side: a jump next to flat or smooth stretches does, a smooth
// profile's changes vary by far less over 2 kWindow + 1 samples. A candidate that is not a jump
// costs only its bisection (~60 evaluations).
constexpr int kWindow = 4;
constexpr double kStandsOut = 4.0;
// A change that survives bisection down to adjacent doubles and is above this fraction of the
// profile's largest value is a jump; a smooth profile changes there by |f'| times an ulp.
constexpr double kJumpFraction = 1e-9;

// (In a fixed array: it runs once per sample, 16384 times per profile located.)
double median_change(const std::vector<double>& change, int i) {
  const int n = static_cast<int>(change.size());
  std::array<double, 2 * kWindow> around;
  int count = 0;
  for (int j = std::max(0, i - kWindow); j <= std::min(n - 1, i + kWindow); ++j)
    if (j != i) around[count++] = change[j];
  if (count == 0) return 0.0;
  std::nth_element(around.begin(), around.begin() + count / 2, around.begin() + count);
  return around[count / 2];
}

// Bisects [a, b] towards the half with the larger change until a and b are adjacent doubles.
ProfileJump bisect(const std::function<double(double)>& f, double a, double b, double* change) {
  double fa = f(a), fb = f(b);
  for (;;) {
    const double m = 0.5 * (a + b);
    if (m <= a || m >= b) break;
    const double fm = f(m);
    if (std::abs(fm - fa) >= std::abs(fb - fm)) {
      b = m;
      fb = fm;
    } else {
      a = m;
      fa = fm;
    }
  }
  *change = std::abs(fb - fa);
  return {a, b};
}

}  // namespace

bool may_jump(const std::string& text) {
  if (text.find_first_of("<>=!&|?") != std::string::npos) return true;
  std::string word;
  for (size_t i = 0; i <= text.size(); ++i) {
    const char c = i < text.size() ? text[i] : ' ';
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '_') {
      word += c;
      continue;
    }
    if (word == "sign" || word == "rint") return true;
    word.clear();
  }
  return false;
}

std::vector<ProfileJump> locate_jumps(const std::function<double(double)>& f, double length) {
  std::vector<double> value(kJumpSamples + 1);
  double scale = 0.0;
  for (int i = 0; i <= kJumpSamples; ++i) {
    value[i] = f(length * i / kJumpSamples);
    if (!std::isfinite(value[i])) return {};  // (the property's check names where)
    scale = std::max(scale, std::abs(value[i]));
  }
  std::vector<double> change(kJumpSamples);
  for (int i = 0; i < kJumpSamples; ++i) change[i] = std::abs(value[i + 1] - value[i]);
  std::vector<ProfileJump> jumps;
  for (int i = 0; i < kJumpSamples; ++i) {
    if (!(change[i] > kStandsOut * median_change(change, i) + kJumpFraction * scale)) continue;
    double left = 0.0;
    const ProfileJump jump = bisect(f, length * i / kJumpSamples, length * (i + 1) / kJumpSamples, &left);
    if (left > kJumpFraction * scale && jump.before > 0.0 && jump.after < length) jumps.push_back(jump);
  }
  return jumps;
}

std::vector<double> check_points(double length, const std::vector<ProfileJump>& jumps) {
  std::vector<double> s;
  s.reserve(kJumpSamples + 1 + 2 * jumps.size());
  for (int i = 0; i <= kJumpSamples; ++i) s.push_back(length * i / kJumpSamples);
  for (const ProfileJump& j : jumps) {
    s.push_back(j.before);
    s.push_back(j.after);
  }
  return s;
}

}  // namespace kirchhoff
