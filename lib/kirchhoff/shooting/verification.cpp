#include "kirchhoff/shooting/verification.hpp"

#include <cmath>
#include <sstream>

#include "kirchhoff/shooting/detail/jacobian_lu.hpp"

namespace kirchhoff {
namespace {

bool finite(const RodPoint& p) {
  return std::isfinite(p.s) && p.r.allFinite() && p.R.allFinite() && p.n.allFinite() && p.m.allFinite() &&
         p.u.allFinite() && p.v.allFinite() && std::isfinite(p.turn_angle);
}

std::string at(double s) {
  std::ostringstream os;
  os.precision(6);
  os << " at s = " << s;
  return os.str();
}

// J^-1 F with J equilibrated by rows and columns first (LAPACK's dgeequ idea): a case in units far
// from 1 has Jacobian entries spread over hundreds of orders of magnitude (a rod of length 1e-100:
// d y(L) / d P ~ L^3), which an unscaled solve reads as rank deficiency. NaN when the equilibrated
// matrix is still singular (rcond below 1e-12), where no correction can be told. This runs on
// every solve that starts converged, so large multiple-shooting matrices go through the sparse LU
// (JacobianLU; its 1-norm condition estimate is Hager's, as the dense rcond): on 4,236 unknowns
// (the exact ply at L/2R = 1000) a dense factorisation takes seconds. Small or dense ones, and
// those the sparse LU cannot factorise, by partial pivoting: after the equilibration the rows are
// of one size; on 1300 unknowns its blocked factorisation takes 0.5 s against full pivoting's 5-6 s.
// `rcond`: the equilibrated matrix's reciprocal condition estimate.
Eigen::VectorXd equilibrated_newton_correction(const Eigen::MatrixXd& J, const Eigen::VectorXd& F, double* rcond) {
  const auto power_of_two_inverse = [](double m) { return m > 0.0 ? std::exp2(-std::ilogb(m)) : 1.0; };
  Eigen::VectorXd rows(J.rows()), columns(J.cols());
  for (int i = 0; i < J.rows(); ++i) rows[i] = power_of_two_inverse(J.row(i).lpNorm<Eigen::Infinity>());
  Eigen::MatrixXd equilibrated = rows.asDiagonal() * J;
  for (int j = 0; j < J.cols(); ++j) {
    columns[j] = power_of_two_inverse(equilibrated.col(j).lpNorm<Eigen::Infinity>());
    equilibrated.col(j) *= columns[j];
  }
  const Eigen::VectorXd scaled_F = rows.asDiagonal() * F;
  if (JacobianLU::sparse_enough(equilibrated)) {
    const JacobianLU lu(equilibrated);
    if (lu.sparse()) {
      *rcond = lu.reciprocal_condition();
      if (!(lu.reciprocal_condition() > 1e-12)) return Eigen::VectorXd::Constant(F.size(), std::nan(""));
      return columns.asDiagonal() * lu.solve(scaled_F);
    }
  }
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(equilibrated);
  *rcond = lu.rcond();
  if (!(lu.rcond() > 1e-12)) return Eigen::VectorXd::Constant(F.size(), std::nan(""));
  return columns.asDiagonal() * lu.solve(scaled_F);
}

}  // namespace

std::string unknowns_failure(const ShootingProblem& problem, const ShootingResult& result) {
  if (!result.x.allFinite()) return "the unknowns hold NaN or inf";
  const Parameters& p = result.parameters;
  for (int i = 0; i < p.size(); ++i)
    if (!std::isfinite(p.values()[i])) return "parameter '" + p.names()[i] + "' is not finite";
  Eigen::VectorXd F;
  std::string failure;
  if (!problem.evaluate(result.x, &F, nullptr, &failure))
    return "the residual cannot be evaluated again at the solution: " + failure;
  const double norm = max_abs_or_nan(F);
  if (!std::isfinite(norm)) return "the residual recomputed at the solution holds NaN or inf";
  // Newton accepts a step that stopped moving at round-off with |F| up to 1e3 times the
  // tolerance (NewtonOptions::step_tolerance); anything beyond is not a converged residual.
  const double tolerance = problem.definition().options.newton.residual_tolerance;
  const double allowed = result.summary.message == "step at round-off" ? 1e3 * tolerance : tolerance;
  if (!(norm <= allowed)) {
    std::ostringstream os;
    os << "the residual recomputed at the solution is " << norm << ", above the tolerance " << allowed;
    return os.str();
  }
  return {};
}

namespace {

// Below this reciprocal condition of the equilibrated step matrix (equilibrated_newton_correction's
// estimate), a large first correction of a small residual is put down to equilibria that are not
// isolated rather than to the case's scale: measured, an isotropic twisted ring closed by clamping
// both ends at one point (a continuous family: the ring turned about its centreline) gives 5.2e-11.
constexpr double kNearlySingular = 1e-6;
// Decades from 1 within which a case's length and stiffness count as of unit scale.
constexpr double kUnitScale = 3.0;

}  // namespace

bool of_unit_scale(double length, double bending) {
  return std::abs(std::log10(length)) <= kUnitScale && std::abs(std::log10(bending)) <= kUnitScale;
}

std::string zero_iteration_failure(const ShootingProblem& problem, const ShootingResult& result) {
  if (result.summary.iterations > 0) return {};
  Eigen::VectorXd F;
  Eigen::MatrixXd J;
  std::string failure;
  // The step matrix where there is one (evaluate_for_step gives the exact one where not): the
  // correction is compared with a bound (1e-4 of the unknowns) far above its relative error (the
  // matrix's tolerance, 1e-8, times its condition).
  const double step_tolerance = problem.definition().options.newton.step_matrix_tolerance;
  if (!problem.evaluate_for_step(result.x, &F, &J, step_tolerance, &failure) || !J.allFinite())
    return {};  // unknowns_failure's job
  double rcond = 0.0;
  const Eigen::VectorXd correction = equilibrated_newton_correction(J, F, &rcond);
  if (!correction.allFinite()) return {};  // singular even when equilibrated: a branch point, say
  const double size = 1.0 + result.x.lpNorm<Eigen::Infinity>();
  const double step = correction.lpNorm<Eigen::Infinity>();
  if (step <= kGuessCorrectionTolerance * size) return {};
  std::ostringstream os;
  os << "the guess meets the residual tolerance as it is (residual " << max_abs_or_nan(F)
     << ", 0 iterations), but one Newton correction from it moves the unknowns by " << step << " against their size "
     << size - 1.0;
  // A nearly singular matrix makes a large correction of a small residual too, at any scale: the
  // equilibria there are not isolated (a continuous family the case does not fix) or branch. On a
  // case far from unit scale the matrix is singular to round-off by its scale alone (a rod 1e-100
  // long), so that is said there.
  const RodModel& model = problem.equations(problem.parameters_at(result.x))->model();
  if (rcond < kNearlySingular && of_unit_scale(model.length, model.B[0](0.0)))
    os << ": the Jacobian is nearly singular there (reciprocal condition " << rcond
       << ", rows and columns equilibrated), so the equilibrium is not isolated: a continuous family of equilibria (a symmetry "
       << "the case leaves free, e.g. turning an isotropic ring about its centreline) or a branch point; fix the "
       << "symmetry in the case, or start from a guess away from the branch point";
  else
    os << ": the absolute tolerance is not meaningful at this case's scale; give lengths, stiffnesses and loads in "
       << "units that make them of order 1";
  return os.str();
}

std::string profile_failure(const RodModel& model, const std::vector<RodPoint>& profile) {
  for (const RodPoint& p : profile)
    if (!finite(p)) return "the solution's profile holds NaN or inf" + at(p.s);
  if (model.extensible)
    for (const RodPoint& p : profile)
      if (!(p.v[2] > 0.0)) {
        std::ostringstream os;
        os << "the rod is compressed to zero or negative length" << at(p.s) << " (stretch v3 = " << p.v[2]
           << "): an extensible rod's sections must keep their orientation along it (v3 > 0), so this solves the "
              "equations, not the rod";
        return os.str();
      }
  if (!model.field) return {};
  for (const RodPoint& p : profile) {
    const double gap = model.field->gap(p.s, p.r);
    // NaN: the field models no wall. A gap <= 0 is on or beyond the wall, where W_ext is
    // infinite or changes sign: outside the potential's domain.
    if (!std::isnan(gap) && !(gap > 0.0)) {
      std::ostringstream os;
      os << "the rod is on or beyond its soft wall" << at(p.s) << " (gap " << gap
         << "), outside the domain of the barrier potential";
      return os.str();
    }
  }
  return {};
}

void mark_check_failure(ShootingResult* result, const std::string& failure) {
  if (failure.empty() || !result->summary.converged()) return;
  result->summary.status = SolverStatus::CheckFailed;
  result->summary.message = failure;
}

}  // namespace kirchhoff
