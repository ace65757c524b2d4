// A pinned column on a Winkler foundation of stiffness k, for the tests that need a badly scaled
// problem with closed-form answers. The case format has no foundation: a soft wall b / (a - y)
// (a = 1) balanced by a uniform weight b / a^2 towards it leaves the straight rod an equilibrium,
// with the foundation's stiffness 2 b / a^3 = k. Its sine modes diagonalise the second variation:
// mode j is critical at P_j = (j pi)^2 + k / (j pi)^2, and its eigenvalue per int theta'^2 is
// P_j - P.
#pragma once

#include <cmath>
#include <string>

namespace kirchhoff::testing {

// The case file's text, with parameters P (the dead compressive end load) and k.
inline std::string foundation_column_case(double P, double k) {
  return "model = \"planar\"\n[parameters]\nP = " + std::to_string(P) + "\nk = " + std::to_string(k) +
         "\nb = \"k/2\"\n"
         "[rod]\nlength = 1.0\nB = 1.0\nbarrier = { b = \"b\", a = 1.0, normal = [0, 1, 0] }\n"
         "gravity = { weight = \"b\", up = [0, -1, 0] }\n"
         "[start]\ntype = \"pinned\"\nposition = [0, 0]\n"
         "[end]\ntype = \"sliding\"\naxis = [1, 0, 0]\nposition = [0, 0]\nforce = [\"-P\", 0]\n"
         "[guess]\nforce = [\"-P\", 0]\n";
}

// P_j, the critical load of the column's mode j.
inline double foundation_column_critical_load(int j, double k) {
  const double x = j * M_PI * j * M_PI;
  return x + k / x;
}

}  // namespace kirchhoff::testing
