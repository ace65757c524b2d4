#include "kirchhoff/jobs/equilibria.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "kirchhoff/analysis/detail/integral_along_rod.hpp"
#include "kirchhoff/analysis/discrete_seed.hpp"
#include "kirchhoff/analysis/discrete_stability.hpp"
#include "kirchhoff/contact/closest_approach.hpp"
#include "kirchhoff/contact/contact.hpp"
#include "kirchhoff/equations/invariants.hpp"
#include "kirchhoff/jobs/detail/equilibrium_families.hpp"
#include "kirchhoff/shooting/link.hpp"
#include "kirchhoff/shooting/verification.hpp"

namespace kirchhoff {

// ---------------------------------------------------------------------------------------------
// Energy

namespace {

// The work of the loads an end condition gives, at the end state p; NaN for a dead couple on a
// spatial end (not a potential in general).
double end_load_work(const EndCondition& end, const RodEquations& eq, const Parameters& params, const RodPoint& p) {
  double work = 0.0;
  for (const auto& c : end.conditions()) {
    if (c.extra || !c.value) continue;
    const Eigen::MatrixXd basis = c.basis(eq);
    if (basis.cols() == 0) continue;
    const Vec3 load = c.value(params);
    if (c.slot == Slot::Force) {
      work += (basis.transpose() * load).dot(basis.transpose() * p.r);
    } else if (c.slot == Slot::Moment) {
      const Vec3 moment = basis * (basis.transpose() * load);
      if (moment.norm() == 0.0) continue;
      if (!eq.is_planar()) return NAN;
      work += moment.z() * p.turn_angle;
    }
  }
  return work;
}

}  // namespace

double total_potential_energy(const ShootingProblem& problem, const Eigen::VectorXd& x) {
  const ProblemDefinition& definition = problem.definition();
  const Parameters params = problem.parameters_at(x);
  // The axial phase condition's unfolding couple (add_axial_phase_condition) is zero at every
  // equilibrium: where it is (unfolding_failure says not otherwise) the rod is the case's own and
  // its energy defined (Michell's ring, which sets the condition, had every energy NaN).
  const auto unfolded = [&](const std::string& name) {
    return is_unfolding_parameter(name) && unfolding_failure(params).empty();
  };
  for (const auto& name : definition.unknown_parameters)
    if ((definition.model_parameters.count(name) || definition.obstacle_parameters.count(name)) && !unfolded(name))
      return NAN;
  const auto eq = problem.equations(params);
  const RodModel& model = eq->model();
  const double L = model.length;
  // 2000 intervals over the rod: Simpson's h^4 error is ~(1/2000)^4 ~ 6e-14 of the energy's
  // scale for a density as smooth as the elastic energy of a resolved rod.
  constexpr int kIntervals = 2000;
  const double energy =
      integral_along_rod(problem, x, model, kIntervals, [&](const RodPoint& p) { return energy_density(model, p); });
  const auto ends = problem.sample(x, {0.0, L});
  return energy - end_load_work(definition.start, *eq, params, ends.front()) -
         end_load_work(definition.end, *eq, params, ends.back());
}

// ---------------------------------------------------------------------------------------------
// Distinctness

double profile_distance(const ShootingProblem& a, const Eigen::VectorXd& xa, const ShootingProblem& b,
                        const Eigen::VectorXd& xb, double force_scale, int samples, bool compare_contacts) {
  const double L = a.length(a.parameters_at(xa));
  const double Lb = b.length(b.parameters_at(xb));
  if (std::abs(L - Lb) > 1e-12 * L) return INFINITY;
  std::vector<double> s(samples);
  for (int i = 0; i < samples; ++i) s[i] = L * i / (samples - 1);
  s.back() = L;
  const auto pa = a.sample(xa, s), pb = b.sample(xb, s);
  // The internal force jumps by a contact's force where the contact acts: a sample there reads
  // one side or the other as round-off puts the contact (the wall's symmetric contact at
  // s = 0.5 +- 5e-13 in two solves read |dn| = its force, and one equilibrium was listed twice).
  // There the force is compared through the contacts themselves: where they are, what they press.
  const auto ca = a.contacts_at(xa), cb = b.contacts_at(xb);
  // (Within 1e-6 L, the scale at which contacts count as in the same place: no sample between
  // two such contacts reads the force across the jump.)
  const double near = 1e-6 * L;
  const auto at_a_jump = [&](double si) {
    for (const auto* set : {&ca, &cb})
      for (const PointContact& c : *set)
        if (std::abs(si - c.s) <= near || (c.extended && std::abs(si - c.s_end) <= near)) return true;
    return false;
  };
  double worst = 0.0;
  if (compare_contacts && ca.size() == cb.size())
    for (size_t k = 0; k < ca.size(); ++k)
      worst = std::max({worst, std::abs(ca[k].s - cb[k].s) / L, std::abs(ca[k].s_end - cb[k].s_end) / L,
                        std::abs(ca[k].force - cb[k].force) / force_scale,
                        std::abs(ca[k].force_end - cb[k].force_end) / force_scale});
  for (int i = 0; i < samples; ++i) {
    // The rotation angle between the frames: ||Ra - Rb||_F = 2 sqrt(2) sin(angle / 2).
    const double frame = 2.0 * std::asin(std::min(1.0, (pa[i].R - pb[i].R).norm() / (2.0 * std::sqrt(2.0))));
    worst = std::max({worst, (pa[i].r - pb[i].r).norm() / L, frame});
    if (!at_a_jump(s[i])) worst = std::max(worst, (pa[i].n - pb[i].n).norm() / force_scale);
  }
  return worst;
}

double axial_orbit_distance(const ShootingProblem& a, const Eigen::VectorXd& xa, const ShootingProblem& b,
                            const Eigen::VectorXd& xb, double force_scale, int samples) {
  const double L = a.length(a.parameters_at(xa));
  if (std::abs(L - b.length(b.parameters_at(xb))) > 1e-12 * L) return INFINITY;
  std::vector<double> s(samples);
  for (int i = 0; i < samples; ++i) s[i] = L * i / (samples - 1);
  s.back() = L;
  const auto pa = a.sample(xa, s), pb = b.sample(xb, s);
  const Vec3 axis_point = pa.front().r;
  // The scaled lab vectors whose (x, y) parts a rotation about e3 turns: r - r(0), d3, n, m.
  const auto parts = [&](const RodPoint& p) {
    return std::array<Vec3, 4>{(p.r - axis_point) / L, p.R.col(2), p.n / force_scale, p.m / (force_scale * L)};
  };
  // The angle that best turns b onto a (least squares over all samples and parts).
  double dot = 0.0, cross = 0.0;
  for (int i = 0; i < samples; ++i) {
    const auto va = parts(pa[i]), vb = parts(pb[i]);
    for (int k = 0; k < 4; ++k) {
      dot += vb[k].x() * va[k].x() + vb[k].y() * va[k].y();
      cross += vb[k].x() * va[k].y() - vb[k].y() * va[k].x();
    }
  }
  const Mat3 Q = Eigen::AngleAxisd(std::atan2(cross, dot), Vec3::UnitZ()).toRotationMatrix();
  double worst = 0.0;
  for (int i = 0; i < samples; ++i) {
    const auto va = parts(pa[i]), vb = parts(pb[i]);
    for (int k = 0; k < 4; ++k) worst = std::max(worst, (Q * vb[k] - va[k]).norm());
  }
  return worst;
}

namespace {

// ---------------------------------------------------------------------------------------------
// Seeds

// The reflection S of a state (S = diag(-1, 1, 1) or diag(1, -1, 1), about the start point r0):
// positions and forces are vectors (S r, S n), the moment a pseudovector (-S m), and the frame
// stays right-handed with d1 -> -S d1, d2 -> S d2, d3 -> S d3. In the plane (S = diag(1, -1, 1))
// this is theta -> -theta, y -> -y, n_y -> -n_y, m_z -> -m_z.
RodPoint reflected(RodPoint p, const Vec3& r0, const Mat3& S) {
  p.r = r0 + S * (p.r - r0);
  p.n = S * p.n;
  p.m = -(S * p.m);
  p.R = S * p.R * Vec3(-1.0, 1.0, 1.0).asDiagonal();
  p.u = Vec3(p.u[0], -p.u[1], -p.u[2]);  // the Darboux vector is a pseudovector: -S u
  p.turn_angle = -p.turn_angle;
  return p;
}

// The same rod traversed from the other end and turned by a half-turn Q about e_z through
// (r(0) + r(L)) / 2, so that it starts where the original starts: r~(s) = r(0) + r(L) - r(L - s),
// theta~(s) = theta(L - s). Traversed backwards, the force and moment that the part beyond s
// exerts change sign (n~ = -Q n, m~ = -Q m) and the frame keeps d2 with d1, d3 reversed before the
// half-turn. With the y -> -y mirror this gives the left-right mirror image of a planar rod
// (a contact at s moves to L - s).
RodPoint reversed_start(RodPoint end, const Vec3& r0) {
  const Mat3 Q = Vec3(-1.0, -1.0, 1.0).asDiagonal();
  end.r = r0;
  end.n = -(Q * end.n);
  end.m = -(Q * end.m);
  end.R = Q * end.R * Vec3(-1.0, 1.0, -1.0).asDiagonal();
  end.u = -end.u;
  end.s = 0.0;
  return end;
}

std::vector<PointContact> reversed_contacts(std::vector<PointContact> contacts, double L) {
  for (auto& c : contacts) {
    if (c.extended) {
      std::swap(c.s, c.s_end);
      std::swap(c.force, c.force_end);
      c.s_end = L - c.s_end;
    }
    c.s = L - c.s;
  }
  std::reverse(contacts.begin(), contacts.end());
  return contacts;
}

std::vector<Mat3> reflections(RodKind kind) {
  const Mat3 flip_y = Vec3(1.0, -1.0, 1.0).asDiagonal();
  if (kind == RodKind::Planar) return {flip_y};
  return {Mat3(Vec3(-1.0, 1.0, 1.0).asDiagonal()), flip_y};
}

// A starting point: either a state at s = 0 whose active set the active-set loop finds (or, for
// rods without obstacles, plain unknowns from it), or unknowns of one family's problem.
struct Seed {
  std::string label;
  // Seeds are taken lowest first: the energy of the equilibrium they were derived from (-inf for
  // the first ones), so the search explores around low-energy equilibria first and --max keeps
  // the lowest ones it can reach.
  double priority = -INFINITY;
  bool far = false;  // a far kick (EquilibriaOptions::far_mode_amplitudes): after every other seed
  bool from_start = true;
  RodPoint start;
  std::vector<PointContact> contacts;  // the starting active set (from_start)
  std::string family;                  // (!from_start)
  Eigen::VectorXd x0;                  // (!from_start)
};

std::string family_key(const std::vector<PointContact>& contacts) {
  std::ostringstream key;
  for (const auto& c : contacts) key << c.obstacle << (c.extended ? 'e' : 'p') << ',';
  return key.str();
}

// The typical magnitude of each unknown: positions L, forces F0, moments F0 L, angles and
// quaternion components 1, contact arclengths L and forces F0, unknown parameters their own
// magnitude (at least 1: they carry no unit the problem knows).
Eigen::VectorXd unknown_scales(const ShootingProblem& problem, double F0) {
  const auto eq = problem.equations(problem.parameters());
  const double L = eq->model().length;
  const int n = problem.state_size();
  Eigen::VectorXd state_scale = Eigen::VectorXd::Ones(n);
  const auto column_used = [&](Slot slot, int j) { return eq->slot_map(slot).col(j).norm() > 0.0; };
  for (int j = 0; j < n; ++j) {
    if (column_used(Slot::Position, j)) state_scale[j] = L;
    if (column_used(Slot::Force, j)) state_scale[j] = F0;
    if (column_used(Slot::Moment, j)) state_scale[j] = F0 * L;
  }
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(problem.size());
  const int M = problem.segments();
  for (int i = 0; i < M; ++i) scale.segment(i * n, n) = state_scale;
  int k = M * n;
  for (const auto& name : problem.definition().unknown_parameters)
    scale[k++] = std::max(1.0, std::abs(problem.parameters().get(name)));
  for (const auto& c : problem.definition().contacts) {
    scale[k++] = L;
    scale[k++] = F0;
    if (c.extended) {
      scale[k++] = L;
      scale[k++] = F0;
    }
  }
  return scale;
}

// Directions along the low modes: the right singular vectors of J diag(scale) with the smallest
// singular values, back in unknowns (unit length in the scaled norm).
std::vector<Eigen::VectorXd> low_mode_directions(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                                 const Eigen::VectorXd& scale, int count) {
  Eigen::VectorXd F;
  Eigen::MatrixXd J;
  std::string failure;
  if (!problem.evaluate(x, &F, &J, &failure) || !J.allFinite()) return {};
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(J * scale.asDiagonal(), Eigen::ComputeFullV);
  std::vector<Eigen::VectorXd> out;
  const int n = static_cast<int>(scale.size());
  for (int k = 0; k < std::min(count, n); ++k) out.push_back(scale.cwiseProduct(svd.matrixV().col(n - 1 - k)));
  return out;
}

// ---------------------------------------------------------------------------------------------
// The search

struct Family {
  std::shared_ptr<ShootingProblem> problem;
  DeflationOperator deflation;
};

class Search {
 public:
  Search(const ProblemDefinition& definition, const RodPoint& guess, const std::vector<std::string>& derived,
         int samples, const EquilibriaOptions& options)
      : definition_(definition), guess_(guess), derived_(derived), samples_(samples), options_(options) {
    deadline_ = deadline_after(options.max_seconds);
    // Every solve of the search (the active-set loops, their fallback searches) ends by then too.
    definition_.options.newton.deadline = std::min(definition_.options.newton.deadline, deadline_);
    // Newton on exact matrices (NewtonOptions::step_matrix_tolerance): the roots deflated and the
    // seeds made from them steer the rest of the search, which a root moved by 1e-13 can change
    // (the Euler column at P = 50 then finds three more rods whose ends meet, or fewer).
    definition_.options.newton.step_matrix_tolerance = 0.0;
    deflated_ = options.deflation;
    deflated_.residual_tolerance = definition.options.newton.residual_tolerance;
    deflated_.step_tolerance = definition.options.newton.step_tolerance;
    deflated_.deadline = std::min(deadline_, definition.options.newton.deadline);
    force_scale_ = force_scale();
  }

  EquilibriaSearch run() {
    // Every known root is considered (each is one polish, not a search), and --max then keeps the
    // lowest in energy: stopping at the first N kept the order they came in (with --set
    // shallow_arch.toml at w = 100 and --max 1, an unstable arch instead of the stable one).
    for (const auto& known : options_.known_roots) consider_known(known);
    push_start(guess_, definition_.contacts, "guess");
    if (options_.mirrors) {
      push_mirrors(guess_, "guess");
      push_half_turn(guess_, "guess", -INFINITY);
    }
    // Ipopt's minimisers too, whatever --max says: minima of the energy, they bring the stable
    // equilibria a search stopped at N may not reach (the wall at Delta = 0.05 with --max 8: eight
    // carried equilibria filled the list, its stable contacts left out).
    if (options_.discrete_seeds) push_discrete_seeds();
    while (!seeds_.empty() && !should_stop()) {
      const auto next = std::min_element(seeds_.begin(), seeds_.end(),
                                         [](const Seed& a, const Seed& b) {
                                           return a.far != b.far ? b.far : a.priority < b.priority;
                                         });
      Seed seed = std::move(*next);
      seeds_.erase(next);
      seed.from_start ? run_start_seed(seed) : run_deflated(seed);
    }
    if (out_.stopped_because.empty()) out_.stopped_because = "seeds exhausted";
    std::stable_sort(out_.equilibria.begin(), out_.equilibria.end(), [](const Equilibrium& a, const Equilibrium& b) {
      return std::isnan(b.energy) ? !std::isnan(a.energy) : a.energy < b.energy;
    });
    if (static_cast<int>(out_.equilibria.size()) > options_.max_equilibria) {  // (the known roots alone)
      out_.equilibria.erase(out_.equilibria.begin() + options_.max_equilibria, out_.equilibria.end());
      out_.stopped_because = "max_equilibria reached";
    }
    out_.families = group_continuous_families(&out_.equilibria, force_scale_, options_.distinct_tolerance,
                                              options_.family_energy_tolerance, options_.compare_samples);
    return std::move(out_);
  }

 private:
  double force_scale() const {
    const ShootingProblem problem(definition_);
    const RodModel& model = problem.equations(problem.parameters())->model();
    const double L = model.length;
    const double B = std::max(model.B[0](0.0), model.B[1](0.0));
    return std::max(B / (L * L), guess_.n.norm());
  }

  // The time or Newton runs spent (should_stop without --max).
  bool past_budget() const {
    return std::chrono::steady_clock::now() > deadline_ || out_.newton_runs >= options_.max_newton_runs;
  }

  bool should_stop() {
    if (static_cast<int>(out_.equilibria.size()) >= options_.max_equilibria)
      out_.stopped_because = "max_equilibria reached";
    else if (std::chrono::steady_clock::now() > deadline_)
      out_.stopped_because = "time limit";
    else if (out_.newton_runs >= options_.max_newton_runs)
      out_.stopped_because = "max_newton_runs";
    return !out_.stopped_because.empty();
  }

  Family& family(const std::vector<PointContact>& contacts) {
    const std::string key = family_key(contacts);
    auto it = families_.find(key);
    if (it != families_.end()) return it->second;
    ProblemDefinition d = definition_;
    d.contacts = contacts;
    auto problem = std::make_shared<ShootingProblem>(d);
    Family f{problem, DeflationOperator(unknown_scales(*problem, force_scale_))};
    return families_.emplace(key, std::move(f)).first->second;
  }

  void push_start(const RodPoint& start, const std::vector<PointContact>& contacts, const std::string& label,
                  double priority = -INFINITY) {
    Seed s;
    s.label = label;
    s.priority = priority;
    s.start = start;
    s.contacts = contacts;
    seeds_.push_back(std::move(s));
  }

  void push_unknowns(const std::string& family, Eigen::VectorXd x0, const std::string& label, double priority,
                     bool far = false) {
    Seed s;
    s.label = label;
    s.priority = priority;
    s.far = far;
    s.from_start = false;
    s.family = family;
    s.x0 = std::move(x0);
    seeds_.push_back(std::move(s));
  }

  void push_mirrors(const RodPoint& start, const std::string& of, double priority = -INFINITY) {
    const auto S = reflections(definition_.kind);
    for (size_t i = 0; i < S.size(); ++i)
      push_start(reflected(start, start.r, S[i]), {}, "mirror " + std::to_string(i + 1) + " of " + of, priority);
  }

  // The planar rod x traversed from its other end (see reversed_start): its left-right mirror and
  // its half-turn.
  void push_reversals(const ShootingProblem& problem, const Eigen::VectorXd& x, const std::string& of,
                      double priority) {
    if (definition_.kind != RodKind::Planar) return;
    const double L = problem.length(problem.parameters_at(x));
    const auto ends = problem.sample(x, {0.0, L});
    const RodPoint start = reversed_start(ends.back(), ends.front().r);
    const auto contacts = reversed_contacts(problem.contacts_at(x), L);
    // The left-right mirror first: it keeps each contact on its side of the rod, at L - s, and an
    // obstacle or field symmetric under it (a wall, a cavity, the soft wall) on its side, so where
    // the supports are symmetric it is the mirror equilibrium itself. From the bare start the
    // active-set loop had missed it (the wall's lowest contact state lost its mirror), and taken
    // after the half-turn (which puts the rod on the obstacle's other side) the budget could end
    // first, in the deflated runs from the half-turn (the soft wall's asymmetric state).
    push_start(reflected(start, start.r, reflections(RodKind::Planar).front()), contacts,
               "mirrored reversal of " + of, priority);
    push_start(start, contacts, "reversal of " + of, priority);
  }

  // The planar rod's start turned by a half-turn about e_z, its forces and moment kept: the loads
  // are dead, so this reverses the rod's direction against them. The straight column under
  // compression, turned, is the straight rod in tension (the global minimum under a dead end
  // load, which no other seed reached); a buckled mode turned starts near the modes that leave
  // the support the other way. Turning the rod against its loads can lower the energy far below
  // its parent's, so the seed is taken in the order of the lower of the two: its parent's and
  // that of the rod integrated from it (without obstacles; with them the parent's).
  void push_half_turn(const RodPoint& start, const std::string& of, double priority) {
    if (definition_.kind != RodKind::Planar) return;
    RodPoint turned = start;
    turned.R = Vec3(-1.0, -1.0, 1.0).asDiagonal() * start.R;
    if (definition_.obstacles.empty()) {
      try {
        const ShootingProblem& problem = *family({}).problem;
        const double energy = total_potential_energy(problem, problem.initial_unknowns(turned));
        if (std::isfinite(energy)) priority = std::min(priority, energy);
      } catch (const std::exception&) {
        // (An integration that fails from the seed: the parent's order.)
      }
    }
    push_start(turned, {}, "half-turn of " + of, priority);
  }

  // Ipopt's minima from the first mode buckled either way, then the same held mirror symmetric:
  // a minimiser left free leaves a symmetric start for a lower asymmetric minimum, and the wall's
  // symmetric rod touching at mid-span (Delta = 0.05, index 1, energy 4.6412) was reached by no
  // starting point (a probe's). On a problem without the symmetry the symmetric minimiser fails
  // its KKT check and is logged, not used.
  void push_discrete_seeds() {
    for (const bool symmetric : {false, true})
      for (const double amplitude : {0.05, -0.05}) {
        if (past_budget()) return;  // (not --max: these are considered as the known roots are)
        const std::string label = std::string("Ipopt seed, ") + (symmetric ? "mirror symmetric, " : "") + "buckled " +
                                  (amplitude > 0 ? "up" : "down");
        DiscreteSolveOptions options;
        options.amplitude = amplitude;
        options.mirror_symmetric = symmetric;
        try {
          ContactSolveResult r = solve_from_discrete_seed(definition_, 200, options);
          ++out_.newton_runs;
          if (!r.result.summary.converged() || !r.complementarity) {
            out_.log.push_back(label + ": the active-set loop did not settle: " + r.message);
            continue;
          }
          Family& f = family(r.definition.contacts);
          // A seed that lands on a root deflated already (the minimiser held symmetric reaching
          // the free one's symmetric rod) leaves the search as it was: deflated twice, the root's
          // factor squared would steer the deflated runs after it differently, for nothing.
          if (f.deflation.nearest_root_distance(r.result.x) <= deflated_.known_root_distance) {
            out_.log.push_back(label + ": again a root found before");
            continue;
          }
          consider(f, r.result.x, label);
        } catch (const std::invalid_argument& e) {
          out_.log.push_back(std::string("Ipopt seeds not used: ") + e.what());
          return;
        } catch (const std::exception& e) {
          out_.log.push_back(label + ": " + e.what());
        }
      }
  }

  // A state at s = 0: without obstacles, unknowns of the contact-free problem; with them, the
  // active-set loop first (it finds the contact set), then deflated runs in that set's family.
  void run_start_seed(const Seed& seed) {
    try {
      if (definition_.obstacles.empty()) {
        Family& f = family({});
        Seed as_unknowns = seed;
        as_unknowns.from_start = false;
        as_unknowns.family = family_key({});
        as_unknowns.x0 = f.problem->initial_unknowns(seed.start);
        run_deflated(as_unknowns);
        return;
      }
      ProblemDefinition d = definition_;
      d.contacts = seed.contacts;
      ContactSolveResult r = solve_with_contacts(d, seed.start);
      ++out_.newton_runs;
      if (!r.result.summary.converged() || !r.complementarity) {
        out_.log.push_back(seed.label + ": the active-set loop did not settle: " +
                           (r.message.empty() ? r.result.summary.brief_report() : r.message));
        return;
      }
      Family& f = family(r.definition.contacts);
      consider(f, r.result.x, seed.label + " (active-set loop)");
      push_unknowns(family_key(r.definition.contacts), f.problem->initial_unknowns(seed.start),
                    seed.label + ", deflated", seed.priority);
    } catch (const std::exception& e) {
      out_.log.push_back(seed.label + ": " + e.what());
    }
  }

  // Farrell's loop: deflated Newton from the same point until it fails, deflating each root.
  void run_deflated(const Seed& seed) {
    Family& f = families_.at(seed.family);
    for (int r = 0; r < options_.restarts_per_seed && !should_stop(); ++r) {
      Eigen::VectorXd x = seed.x0;
      const NewtonSummary s = deflated_newton(*f.problem, x, f.deflation, deflated_);
      ++out_.newton_runs;
      if (!s.converged()) {
        out_.log.push_back(seed.label + ": run " + std::to_string(r + 1) + " ends: " + s.message);
        return;
      }
      consider(f, x, r == 0 ? seed.label : seed.label + " (deflated run " + std::to_string(r + 1) + ")");
    }
  }

  // Other active sets next to x's: each point contact that may lie flat on its obstacle, made an
  // extended contact over kSpread L around it (a rod pressed further lies on the wall: the flat
  // contact coexists with point contacts), and each extended contact made a point contact at its
  // middle, and two at its ends (its middle lifted off, as a flat part pressed past its Euler
  // load buckles: the wall's hanging fold at Delta = 0.05, touching at s = 0.3036 and 0.6964, lies
  // next to its flat contact over [0.3198, 0.6802]). The active-set loop corrects them.
  void push_contact_variants(const ShootingProblem& problem, const Eigen::VectorXd& x, const std::string& of,
                             double priority) {
    constexpr double kSpread = 0.05;
    const Parameters p = problem.parameters_at(x);
    const double L = problem.length(p);
    const auto obstacles = problem.obstacles(p);
    const auto contacts = problem.contacts_at(x);
    const RodPoint start = problem.sample(x, {0.0}).front();
    for (size_t k = 0; k < contacts.size(); ++k) {
      std::vector<PointContact> variant = contacts;
      PointContact& c = variant[k];
      if (c.extended) {
        c.s = 0.5 * (c.s + c.s_end);
        c.force += c.force_end;
        c.extended = false;
      } else {
        if (!extended_contact_unsupported(*problem.equations(p), obstacles[c.obstacle]).empty()) continue;
        c.extended = true;
        c.s_end = std::min(c.s + 0.5 * kSpread * L, L);
        c.s = std::max(c.s - 0.5 * kSpread * L, 0.0);
        c.force_end = c.force = 0.5 * c.force;
      }
      push_start(start, variant, std::string(c.extended ? "flat" : "point") + " contact variant of " + of, priority);
      if (contacts[k].extended) push_start(start, lifted_middle(contacts, k), "lifted flat contact of " + of, priority);
    }
  }

  // `contacts` with the k-th (extended) made point contacts at its two ends, each with its end's force.
  static std::vector<PointContact> lifted_middle(std::vector<PointContact> contacts, size_t k) {
    PointContact second = contacts[k];
    contacts[k].extended = second.extended = false;
    second.s = second.s_end;
    second.force = second.force_end;
    contacts.insert(contacts.begin() + static_cast<std::ptrdiff_t>(k) + 1, second);
    return contacts;
  }

  // Why x is not an admissible equilibrium of its family's problem, or "".
  std::string inadmissibility(const ShootingProblem& problem, const Eigen::VectorXd& x) const {
    const Parameters p = problem.parameters_at(x);
    if (p.contains(kUnfoldingParameter) && std::abs(p.get(kUnfoldingParameter)) > kUnfoldingTolerance)
      return "the symmetry-unfolding parameter is not zero (a solution of the unfolded system only)";
    if (problem.definition().obstacles.empty()) return "";
    std::ostringstream why;
    const ClosestApproach gap = closest_approach(problem, x, 401);
    if (gap.gap < -options_.penetration_tolerance) {
      why << "penetrates obstacle " << gap.obstacle << " by " << -gap.gap << " at s = " << gap.s;
      return why.str();
    }
    for (const auto& c : problem.contacts_at(x)) {
      const double force = c.extended ? std::min(c.force, c.force_end) : c.force;
      const double pressure = problem.smallest_wrap_pressure(x, c);
      if (force < -options_.force_tolerance || (std::isfinite(pressure) && pressure < -options_.force_tolerance)) {
        why << "the contact at s = " << c.s << " pulls on obstacle " << c.obstacle << " (force " << force << ")";
        return why.str();
      }
    }
    return "";
  }

  // max |F| at x as Newton judges it, and the Newton step there. Integrated with the
  // sensitivities, whose error control takes smaller steps than the state's alone: without them
  // the residual carries more of the integrator's error, which grows with the shooting's
  // sensitivity (on the Euler column at P = 100 its first mode read 3e-10 without them and 1e-12
  // with them, and every root near the tolerance 1e-10 was rejected).
  struct RootCheck {
    bool evaluated = false;
    double residual = NAN;
    double step = NAN;  // max |J^-1 F|
  };
  static RootCheck check_root(const ShootingProblem& problem, const Eigen::VectorXd& x, std::string* failure) {
    Eigen::VectorXd F;
    Eigen::MatrixXd J;
    RootCheck c;
    c.evaluated = problem.evaluate(x, &F, &J, failure);
    if (!c.evaluated) return c;
    c.residual = max_abs_or_nan(F);
    if (std::isfinite(c.residual) && J.allFinite())
      c.step = Eigen::PartialPivLU<Eigen::MatrixXd>(J).solve(F).lpNorm<Eigen::Infinity>();
    return c;
  }
  // A root as Newton's tests have it: within the tolerance, or with its step at round-off.
  bool is_root(const RootCheck& c, const Eigen::VectorXd& x) const {
    return c.residual <= deflated_.residual_tolerance ||
           step_at_round_off(c.step, x.lpNorm<Eigen::Infinity>(), c.residual, deflated_.step_tolerance,
                             deflated_.residual_tolerance);
  }

  // A root deflated Newton reached at the tolerance may read a few times above it when evaluated
  // again (the integrator's steps differ from its last iterate's). A few plain Newton steps
  // settle it, kept only when they stay within the distinctness scale of the root (so they
  // cannot move to another).
  void polish(const ShootingProblem& problem, const DeflationOperator& deflation, Eigen::VectorXd& x) const {
    std::string failure;
    const RootCheck c = check_root(problem, x, &failure);
    if (!std::isfinite(c.residual) || is_root(c, x)) return;
    NewtonOptions newton = definition_.options.newton;
    newton.max_iterations = 4;
    newton.fallback_search = false;
    Eigen::VectorXd polished = x;
    const NewtonSummary s = newton_solve(problem, polished, newton);
    if (s.converged() && deflation.distance(polished, x) < options_.distinct_tolerance) x = polished;
  }

  // An equilibrium known beforehand, on its active set (a start that does not fit the problem is
  // logged and left out). One whose residual, polished, is still above the tolerance is not
  // deflated (which would keep the search from the root it approximates) but searched from:
  // the Euler column's first mode at P = 100, carried from the file's P = 12 to a residual of
  // 1.6e-10 (its sensitivity grows like exp(sqrt(P) L)), was rejected and deflated, and with it
  // the rod the search had found before.
  void consider_known(const EquilibriaOptions::KnownRoot& known) {
    try {
      Family& f = family(known.contacts);
      if (known.x.size() != f.problem->size()) {
        out_.log.push_back(known.found_by + ": its unknowns do not fit the problem; not used");
        return;
      }
      Eigen::VectorXd x = known.x;
      polish(*f.problem, f.deflation, x);
      std::string failure;
      const RootCheck root = check_root(*f.problem, x, &failure);
      if (root.evaluated && !is_root(root, x)) {
        std::ostringstream why;
        why << known.found_by << ": residual " << root.residual << " above the tolerance; searched from instead";
        out_.log.push_back(why.str());
        // In the order of its energy among the other seeds (those of the roots found), as a seed
        // made from an equilibrium is: first of all, it took --max's places from the mirror of a
        // lower equilibrium (the spatial cantilever at P = 30: its global minimum's mirror).
        double priority = -INFINITY;
        try {
          if (const double energy = total_potential_energy(*f.problem, x); std::isfinite(energy)) priority = energy;
        } catch (const std::exception&) {
          // (Not integrable: first, as before.)
        }
        push_unknowns(family_key(known.contacts), std::move(x), known.found_by, priority);
        return;
      }
      consider(f, std::move(x), known.found_by);
    } catch (const std::exception& e) {
      out_.log.push_back(known.found_by + ": " + e.what());
    }
  }

  // A converged root: deflated from now on; reported if it is a new admissible equilibrium.
  void consider(Family& f, Eigen::VectorXd x, const std::string& label) {
    polish(*f.problem, f.deflation, x);
    f.deflation.add_root(x);
    ShootingResult result;
    result.x = x;
    result.parameters = f.problem->parameters_at(x);
    std::string failure;
    const RootCheck root = check_root(*f.problem, x, &failure);
    if (!root.evaluated) return reject(label, "cannot be re-evaluated: " + failure, NAN);
    result.summary.status = SolverStatus::Converged;
    result.summary.residual_norm = root.residual;
    if (!is_root(root, x)) return reject(label, "residual above the tolerance", root.residual);
    if (!(root.residual <= deflated_.residual_tolerance)) result.summary.message = "step at round-off";
    if (const std::string why = inadmissibility(*f.problem, x); !why.empty()) {
      reject(label, why, result.summary.residual_norm);
      // The active-set loop from the same rod may find the admissible equilibrium nearby.
      if (!definition_.obstacles.empty())
        push_start(f.problem->sample(x, {0.0}).front(), f.problem->contacts_at(x), "active set corrected from " + label,
                   -INFINITY);
      return;
    }
    mark_check_failure(&result, link_failure(*f.problem, x));
    Solution sol = make_solution(*f.problem, std::move(result), samples_, derived_);
    if (!sol.result.summary.converged())
      return reject(label, sol.result.summary.message, sol.result.summary.residual_norm);
    // (Computed before the comparison only where it decides it: spatial rods.)
    std::optional<StabilityReport> stability;
    if (definition_.kind == RodKind::Spatial) stability = stability_of(*f.problem, x);
    // A spatial equilibrium with a zero mode lies on a continuous family: for the isotropic rod
    // with both ends on the e3 axis, rotating it about the axis (the cross-sections turned back)
    // gives the same equilibrium again, which Newton lands on anywhere along the circle. Those
    // are compared modulo that rotation, so a circle is listed once.
    const bool on_orbit = stability && stability->zero_modes > 0;
    const bool forceless_edge = has_forceless_edge(sol.contacts), flat = has_extended_contact(sol.contacts);
    for (size_t i = 0; i < out_.equilibria.size(); ++i) {
      const Equilibrium& e = out_.equilibria[i];
      const bool forceless = forceless_edge || has_forceless_edge(e.solution.contacts);
      const bool loose = flat || has_extended_contact(e.solution.contacts);  // (a forceless edge is one's)
      const double d = profile_distance(*e.problem, e.solution.result.x, *f.problem, x, force_scale_,
                                        options_.compare_samples, !forceless);
      const bool same = d < (loose ? singular_root_distance() : options_.distinct_tolerance) ||
                        (on_orbit && axial_orbit_distance(*e.problem, e.solution.result.x, *f.problem, x, force_scale_,
                                                          options_.compare_samples) < options_.distinct_tolerance);
      if (same) {
        out_.log.push_back(label + ": again equilibrium found by " + e.found_by);
        return;
      }
    }
    accept(f, std::move(sol), stability ? std::move(*stability) : stability_of(*f.problem, x), label);
  }

  // The conjugate points' index, or where they leave it undefined the discretised energy's, as
  // solve reports it.
  static StabilityReport stability_of(const ShootingProblem& problem, const Eigen::VectorXd& x) {
    return with_discretised_index_where_undefined(analyse_stability(problem, x), problem, x, true);
  }

  // An extended contact whose edge carries no force: the rod beyond the edge lies on the obstacle
  // by itself, so the edge could sit anywhere it does, and the root is one of a continuum (the
  // wall pushed to Delta = 0.06 gave one flat contact split at fifteen places, listed fifteen
  // times). Along that continuum the Jacobian is singular and Newton fixes the root only to about
  // the square root of its tolerance (profiles 1.7e-6 apart in d3), so such roots are compared at
  // that scale (singular_root_distance).
  bool has_forceless_edge(const std::vector<PointContact>& contacts) const {
    const double zero = options_.force_tolerance * std::max(1.0, force_scale_);
    return std::any_of(contacts.begin(), contacts.end(), [zero](const PointContact& c) {
      return c.extended && (std::abs(c.force) <= zero || std::abs(c.force_end) <= zero);
    });
  }
  // An extended contact's edges are where the rod meets the obstacle tangentially, and Newton
  // fixes them, and the rod with them, less well than an isolated root: the wall at Delta = 0.04
  // reached along two homotopies (case_equilibria.cpp) had its flat contact's edges 7e-8 and
  // 2.5e-7 apart and the frames 1.04e-6 apart at residuals of 4e-13 and 8e-13, and was listed
  // twice. Rods with one are compared at singular_root_distance too (their contacts as well, unless
  // an edge carries no force).
  static bool has_extended_contact(const std::vector<PointContact>& contacts) {
    return std::any_of(contacts.begin(), contacts.end(), [](const PointContact& c) { return c.extended; });
  }
  // sqrt of the residual tolerance, with a factor of 10 to spare: 1e-4 at the default 1e-10.
  double singular_root_distance() const {
    return std::max(options_.distinct_tolerance, 10.0 * std::sqrt(deflated_.residual_tolerance));
  }

  void reject(const std::string& label, const std::string& reason, double residual) {
    out_.rejected.push_back({label, reason, residual});
    out_.log.push_back(label + ": rejected: " + reason);
  }

  void accept(Family& f, Solution sol, StabilityReport stability, const std::string& label) {
    Equilibrium e;
    e.problem = f.problem;
    e.energy = total_potential_energy(*f.problem, sol.result.x);
    e.stability = std::move(stability);
    e.found_by = label;
    e.solution = std::move(sol);
    const Eigen::VectorXd x = e.solution.result.x;
    const std::string name = "#" + std::to_string(out_.equilibria.size() + 1);
    out_.log.push_back(label + ": new equilibrium " + name);
    const double priority = std::isnan(e.energy) ? INFINITY : e.energy;
    out_.equilibria.push_back(std::move(e));
    if (options_.mirrors) {
      const RodPoint start = f.problem->sample(x, {0.0}).front();
      push_mirrors(start, name, priority);
      push_reversals(*f.problem, x, name, priority);
      push_half_turn(start, name, priority);
    }
    push_contact_variants(*f.problem, x, name, priority);
    const std::string key = family_key(f.problem->definition().contacts);
    // On a single-shooting problem (its unknowns one state and a few contacts) every singular
    // direction is tried, the ones past the low modes at the first amplitude only: a 3D
    // cantilever under 4 times its critical load (B1 = 1, B2 = 1.5, P = 10) has its buckled rods
    // (tip deflection 0.62 L, clamping moment 6.2) along directions the straight rod's smallest
    // singular values do not point to, and the search listed the straight rod alone (22 Newton
    // runs; now the four buckled rods too, in 239).
    const int unknowns = static_cast<int>(x.size());
    const auto modes = low_mode_directions(*f.problem, x, f.deflation.scale(),
                                           f.problem->segments() == 1 ? unknowns : options_.low_modes);
    const size_t low = static_cast<size_t>(options_.low_modes);
    for (const bool far : {false, true})
      for (const double amplitude : far ? options_.far_mode_amplitudes : options_.mode_amplitudes)
        for (size_t k = 0; k < modes.size(); ++k) {
          if (k >= low && (far || amplitude != options_.mode_amplitudes.front())) continue;
          for (const double sign : {1.0, -1.0})
            push_unknowns(key, x + sign * amplitude * modes[k],
                          std::string(far ? "far kick along low mode " : k < low ? "low mode " : "mode ") +
                              std::to_string(k + 1) + (sign > 0 ? "+" : "-") + " of " + name,
                          priority, far);
        }
  }

  ProblemDefinition definition_;
  RodPoint guess_;
  std::vector<std::string> derived_;
  int samples_;
  EquilibriaOptions options_;
  DeflatedNewtonOptions deflated_;
  std::chrono::steady_clock::time_point deadline_;
  double force_scale_ = 1.0;
  std::map<std::string, Family> families_;
  std::deque<Seed> seeds_;
  EquilibriaSearch out_;
};

}  // namespace

std::string EquilibriaOptions::validate() const {
  if (max_equilibria < 1 || max_equilibria > 1000) return "max (equilibria) must be in [1, 1000]";
  if (!(max_seconds >= 0 && max_seconds <= 1e9)) return "max_seconds must be in [0, 1e9] (0: no limit)";
  return "";
}

EquilibriaSearch find_equilibria(const ProblemDefinition& definition, const RodPoint& guess,
                                 const std::vector<std::string>& derived_names, int samples,
                                 const EquilibriaOptions& options) {
  if (options.max_equilibria < 1 || options.restarts_per_seed < 1 || options.low_modes < 0 ||
      std::any_of(options.mode_amplitudes.begin(), options.mode_amplitudes.end(), [](double a) { return !(a > 0); }) ||
      std::any_of(options.far_mode_amplitudes.begin(), options.far_mode_amplitudes.end(),
                  [](double a) { return !(a > 0); }) ||
      !(options.distinct_tolerance > 0) || !(options.family_energy_tolerance > 0) || options.compare_samples < 2 ||
      !(options.max_seconds >= 0))
    throw std::invalid_argument("equilibria: invalid options (counts >= 1, amplitudes and tolerances > 0)");
  return Search(definition, guess, derived_names, samples, options).run();
}

}  // namespace kirchhoff
