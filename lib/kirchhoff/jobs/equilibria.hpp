// All the equilibria at one set of parameters: a search by deflated Newton (deflation.hpp) from
// several kinds of starting points, keeping only distinct, converged, admissible equilibria.
//
// Starting points (seeds), taken in this order, each one run repeatedly with deflated Newton
// (every run deflating the roots found so far, as Farrell, Birkisson & Funke do) until a run fails:
//   - the case's guess, and its mirror images (planar: y -> -y, theta -> -theta; spatial: the
//     reflections in the planes x = x(0) and y = y(0));
//   - Ipopt's minimisers of the discretised energy (discrete_seed.hpp) buckled to either side,
//     where that model applies (planar rods clamped at both ends);
//   - for every equilibrium found: its mirror images (planar: also the rod traversed from its
//     other end, turned by a half-turn, which maps a contact at s to L - s), and perturbations along the low modes of
//     the second variation, taken as the right singular vectors of the scaled shooting Jacobian
//     with the smallest singular values (the Jacobi fields that come closest to meeting all the
//     end conditions: near a bifurcation these are its null vectors).
// With obstacles the unknowns include the active contact set, so the search keeps one deflation
// per active set (a "family"). A seed whose active set is not known is solved by the active-set
// loop (contact.hpp); a deflated root that is inadmissible (penetrating, or a contact pulling) is
// deflated as well (so it is not found again) but never reported: the active-set loop is run from
// it instead, which may lead to an admissible equilibrium with another contact set.
//
// Distinctness is judged on the rod itself, scale-free: two equilibria are the same when their
// profiles differ by less than distinct_tolerance in max_s (|dr| / L, the frame's rotation in
// radians, |dn| / F0), F0 = max(B / L^2, |n(0)| of the case's guess) - never on raw shooting
// unknowns, whose scales (and, with contacts, whose meaning) differ. A spatial equilibrium with a
// zero mode is compared modulo rotations about e3 as well (axial_orbit_distance): the isotropic
// rod clamped on the axis has circles of equilibria, each listed once.
//
// Equilibria with zero modes are not isolated: each is one point of a continuous family (or a
// bifurcation point). Members of one family that the search found as distinct points are grouped
// (Equilibrium::family: equal energies and a rigid motion between them, equilibrium_families.hpp),
// never dropped.
//
// Every reported equilibrium has passed: max |F| <= the case's Newton tolerance, the solution's
// own checks (verification.hpp, link.hpp), and with obstacles 0 <= gap perp force >= 0 (gap >=
// -penetration_tolerance along the rod, every contact force >= -force_tolerance, wrapped parts
// pressing). Points that fail are listed as rejected with the reason.
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/continuation/deflation.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

struct EquilibriaOptions {
  int max_equilibria = 16;     // stop once this many distinct equilibria are found
  int restarts_per_seed = 6;   // deflated runs from one seed (each deflating all roots so far)
  int max_newton_runs = 400;   // over the whole search: bounds its cost on hard cases
  int low_modes = 2;           // smallest singular directions perturbed along, per equilibrium
  // Perturbations along a low mode, in scaled units (radians, rod lengths, F0): 0.5 leaves the
  // found root's basin for equilibria a sizeable change of shape away (the next buckled mode);
  // 0.05 stays near it, for equilibria close by (a contact that moved slightly off mid-span),
  // where a large kick sends Newton past them.
  std::vector<double> mode_amplitudes{0.5, 0.05};
  // Kicks along the same low modes far beyond the root's neighbourhood, tried only once every
  // other starting point is exhausted (so that a search --max stops keeps what the near seeds
  // find first): branches of finite amplitude that no near seed reaches, such as the
  // subcritical buckled rod of `twisted_clamped.toml` at phi = 10, reactions ~4 F0 away from
  // the straight rod's (found from a kick of 8, not of 4: deflated Newton's steps are at most 2
  // scaled units, and a longer kick keeps it on the mode's side).
  std::vector<double> far_mode_amplitudes{8.0};
  bool mirrors = true;
  bool discrete_seeds = true;  // Ipopt's seeds where discrete_seed.hpp applies
  // Equilibria known beforehand (the one `solve` reports, reached by homotopy: case_equilibria.hpp),
  // considered before any seed, so that the list holds them and explores around them.
  struct KnownRoot {
    std::vector<PointContact> contacts;  // its active set
    Eigen::VectorXd x;                   // its unknowns on that set
    std::string found_by;
  };
  std::vector<KnownRoot> known_roots;
  // Profiles closer than this (scale-free, see above) are one equilibrium. Converged profiles
  // are accurate to ~1e-9 (integrator at 1e-12, residuals at 1e-10 amplified by the Jacobian's
  // conditioning); distinct equilibria differ at O(1) unless they sit within 1e-6 of a
  // bifurcation, where they are not distinct in any useful sense.
  double distinct_tolerance = 1e-6;
  int compare_samples = 101;   // where profiles are compared
  // Equilibria with zero modes whose energies agree to this (relative to |E| + F0 L) and that a
  // rigid motion maps onto each other (within distinct_tolerance) are members of one continuous
  // family (equilibrium_families.hpp). Energies are computed to ~1e-13 of their scale (Simpson,
  // below), and a family's members have exactly equal energies: 1e-8 leaves five orders for the
  // solve's error, while distinct equilibria differ at O(1) (or within 1e-8 of a bifurcation).
  double family_energy_tolerance = 1e-8;
  // Complementarity, as contact.hpp's active-set loop judges it.
  double penetration_tolerance = 1e-9;
  double force_tolerance = 1e-9;
  double max_seconds = 120.0;  // wall-clock limit of the whole search (0: none)
  DeflatedNewtonOptions deflation;  // residual_tolerance is taken from the case's Newton options

  // "" when the user's settings (max_equilibria, max_seconds) are valid, else the reason (bad
  // input for both front ends).
  std::string validate() const;
};

struct Equilibrium {
  std::shared_ptr<const ShootingProblem> problem;  // with the active contact set it was solved in
  Solution solution;
  StabilityReport stability;
  double energy = 0.0;   // total_potential_energy
  std::string found_by;  // which seed led to it
  // The continuous family it belongs to (1, 2, ...), where it has zero modes; 0 for an isolated
  // equilibrium or one whose index is not defined (equilibrium_families.hpp).
  int family = 0;
};

struct RejectedPoint {
  std::string found_by;
  std::string reason;
  double residual = 0.0;
};

struct EquilibriaSearch {
  std::vector<Equilibrium> equilibria;  // distinct, converged, admissible; by increasing energy
  std::vector<RejectedPoint> rejected;  // converged points that are not equilibria, with why
  std::vector<std::string> log;         // one line per seed and outcome
  int newton_runs = 0;
  int families = 0;  // continuous families among the equilibria (Equilibrium::family)
  // Why the search ended: "seeds exhausted", "max_equilibria reached", "time limit", "max_newton_runs".
  std::string stopped_because;
};

// Searches from the definition (its contacts the starting active set) and the guess of the state at
// s = 0; derived_names and samples as make_solution takes them. Throws std::invalid_argument for
// invalid options.
EquilibriaSearch find_equilibria(const ProblemDefinition& definition, const RodPoint& guess,
                                 const std::vector<std::string>& derived_names, int samples,
                                 const EquilibriaOptions& options = {});

// Total potential energy of the equilibrium x: the integral of the energy density V = W_bend +
// W_shear + W_ext (invariants.hpp) along the rod, minus the work of the end loads the case gives
// (F.r at each end for every given force component, and for planar rods M theta for a given
// moment). Contact forces do no work (the rod is on the rigid obstacle where they act). The
// integral is composite Simpson between the contacts' arclengths (the density is smooth there:
// error ~ h^4, ~1e-13 of the energy with 2000 intervals); NaN where the energy is not a potential:
// a dead couple on a spatial end free to rotate, or an unknown parameter that changes the rod or
// an obstacle (a sleeve's sliding length: the work the sleeve's load does as the rod slides is not
// part of this energy, so comparing such equilibria by it would mislead) - but the axial phase
// condition's unfolding parameter where it is zero, as at every equilibrium.
double total_potential_energy(const ShootingProblem& problem, const Eigen::VectorXd& x);

// The scale-free distance between two solutions (see above) over `samples` points. Without
// `compare_contacts`, the lists of contacts are not compared, only the rod: for one equilibrium
// written with different contact sets (a flat part whose forceless edge may sit anywhere the rod
// lies on the obstacle).
double profile_distance(const ShootingProblem& a, const Eigen::VectorXd& xa, const ShootingProblem& b,
                        const Eigen::VectorXd& xb, double force_scale, int samples = 101,
                        bool compare_contacts = true);

// The same modulo a rotation about the e3 axis through a's r(0) (the angle fitted by least squares):
// the largest difference of (r - r(0)) / L, d3, n / F0 and m / (F0 L) along the rod. The director
// d1 is left out, since the rotation of an isotropic rod's family turns its cross-sections back.
double axial_orbit_distance(const ShootingProblem& a, const Eigen::VectorXd& xa, const ShootingProblem& b,
                            const Eigen::VectorXd& xb, double force_scale, int samples = 101);

}  // namespace kirchhoff
