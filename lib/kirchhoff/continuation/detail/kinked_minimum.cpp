#include "kirchhoff/continuation/detail/kinked_minimum.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

namespace kirchhoff::detail {
namespace {

constexpr double kGolden = 0.3819660112501051;  // (3 - sqrt 5) / 2
// A fit must bring the bracket to this fraction of its width within two steps, or a golden
// section replaces it (golden sections alone give 0.618 per step, 0.38 per two).
constexpr double kRequiredShrink = 0.6;
// A fit closer than this fraction of the bracket to the lowest sample is replaced by a probe.
constexpr double kProbeBelow = 1e-3;

// A line through two samples: value(h) = value + slope (h - h).
struct Line {
  double h, value, slope;
  double at(double x) const { return value + slope * (x - h); }
};

Line through(const MinimumSample& p, const MinimumSample& q) { return {p.h, p.value, (q.value - p.value) / (q.h - p.h)}; }

// Where a falling line (left of the kink) meets a rising one (right of it), inside [lo, hi].
std::optional<double> kink(const Line& falling, const Line& rising, double lo, double hi) {
  if (!(falling.slope < 0.0 && rising.slope > 0.0) || !std::isfinite(falling.slope) || !std::isfinite(rising.slope))
    return std::nullopt;
  const double h = (rising.value - falling.value + falling.slope * falling.h - rising.slope * rising.h) /
                   (falling.slope - rising.slope);
  if (!(h >= lo && h <= hi)) return std::nullopt;
  return h;
}

// The next trial from the samples (sorted by h, `i` the lowest, with a neighbour on each side):
// for each side the kink may lie on, the falling line through the lowest sample and its
// neighbour on the other side, met by the rising line through the two nearest samples beyond
// (or, with one sample there, the falling line's mirror through it: a V with equal slopes).
// Where both sides give a kink, the one whose lines meet lower.
std::optional<double> fitted_trial(const std::vector<MinimumSample>& s, std::size_t i) {
  std::optional<double> best;
  double best_value = INFINITY;
  auto consider = [&](const std::optional<double>& h, const Line& line) {
    if (h && line.at(*h) < best_value) {
      best = h;
      best_value = line.at(*h);
    }
  };
  {  // the kink right of s[i]
    const Line falling = through(s[i - 1], s[i]);
    const Line rising = i + 2 < s.size() ? through(s[i + 1], s[i + 2]) : Line{s[i + 1].h, s[i + 1].value, -falling.slope};
    consider(kink(falling, rising, s[i].h, s[i + 1].h), falling);
  }
  {  // the kink left of s[i]
    const Line rising = through(s[i], s[i + 1]);
    const Line falling = i >= 2 ? through(s[i - 2], s[i - 1]) : Line{s[i - 1].h, s[i - 1].value, -rising.slope};
    consider(kink(falling, rising, s[i - 1].h, s[i].h), rising);
  }
  return best;
}

// Beside the lowest sample, towards its farther neighbour, at twice the distance to the kink of a
// V through zero with the neighbours' mean slope (the mirror image of the lowest sample), so that
// both sides get a sample close to the kink and the next fit's lines come from near samples.
double probe(const MinimumSample& lo, const MinimumSample& mid, const MinimumSample& hi, double tolerance) {
  const double slope = 0.5 * ((lo.value - mid.value) / (mid.h - lo.h) + (hi.value - mid.value) / (hi.h - mid.h));
  // At most a quarter of the way to the nearer neighbour (the V may not reach zero, and then the
  // distance is overestimated), so that the probes close in on the lowest sample.
  const double nearer = std::min(mid.h - lo.h, hi.h - mid.h);
  double d = std::min(2.0 * mid.value / slope, 0.25 * nearer);
  d = std::isfinite(d) ? std::max(d, 0.5 * tolerance) : 0.5 * tolerance;
  return hi.h - mid.h > mid.h - lo.h ? std::min(mid.h + d, 0.5 * (mid.h + hi.h)) : std::max(mid.h - d, 0.5 * (lo.h + mid.h));
}

double golden_trial(const MinimumSample& a, const MinimumSample& m, const MinimumSample& b) {
  return b.h - m.h > m.h - a.h ? m.h + kGolden * (b.h - m.h) : m.h - kGolden * (m.h - a.h);
}

}  // namespace

KinkedMinimum minimise_kinked(const std::function<double(double)>& f, MinimumSample a, MinimumSample m,
                              MinimumSample b, double tolerance, int max_evaluations) {
  KinkedMinimum out;
  out.best = m;
  if (!(a.h < m.h && m.h < b.h) || !(m.value <= a.value && m.value <= b.value)) {
    out.bracketed = false;
    return out;
  }
  std::vector<MinimumSample> samples = {a, m, b};  // sorted by h; samples[i] the lowest
  std::size_t i = 1;
  double width_two_steps_ago = b.h - a.h, width_one_step_ago = b.h - a.h;
  while (out.evaluations < max_evaluations && samples[i + 1].h - samples[i - 1].h > tolerance &&
         samples[i].value > 0.0) {
    const MinimumSample &lo = samples[i - 1], &mid = samples[i], &hi = samples[i + 1];
    const double width = hi.h - lo.h;
    const bool fits_pay = width <= kRequiredShrink * width_two_steps_ago || out.evaluations < 2;
    std::optional<double> trial = fits_pay ? fitted_trial(samples, i) : std::nullopt;
    // A fit that lands on the lowest sample teaches little: its lines may come from far samples.
    if (trial && std::abs(*trial - mid.h) < kProbeBelow * width) *trial = probe(lo, mid, hi, tolerance);
    const double h = trial && *trial > lo.h && *trial < hi.h ? *trial : golden_trial(lo, mid, hi);
    const double lowest = mid.value;
    const MinimumSample s{h, f(h)};
    ++out.evaluations;
    const auto k = static_cast<std::size_t>(
        std::upper_bound(samples.begin(), samples.end(), h, [](double x, const MinimumSample& q) { return x < q.h; }) -
        samples.begin());
    samples.insert(samples.begin() + static_cast<std::ptrdiff_t>(k), s);  // (lo, mid, hi dangle from here)
    if (s.value < lowest) i = k;
    else if (k <= i) ++i;
    width_two_steps_ago = width_one_step_ago;
    width_one_step_ago = width;
  }
  out.best = samples[i];
  return out;
}

}  // namespace kirchhoff::detail
