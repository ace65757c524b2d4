// Ipopt's application object, from the library loaded when it is first needed.
//
// Ipopt and the MUMPS it solves with are nine shared libraries whose loading cost every process a
// millisecond (docs/performance.md, "The CLI against the library"), while only the discretised
// energies need them (the Ipopt seed, the discrete stability check, the exact ply's contact). So
// the library is not linked: the first call opens it (dlopen) and finds IpoptApplicationFactory,
// the one function of it our code calls; everything else goes through the application's virtual
// functions. (The sources that use Ipopt are compiled with -fno-devirtualize-speculatively: GCC's
// speculative devirtualisation otherwise refers to the vtables of Ipopt's option classes.)
#pragma once

#include <IpIpoptApplication.hpp>

namespace kirchhoff::detail {

// A new IpoptApplication. Throws std::runtime_error naming the library and dlopen's reason when
// Ipopt cannot be loaded.
Ipopt::SmartPtr<Ipopt::IpoptApplication> make_ipopt_application();

}  // namespace kirchhoff::detail
