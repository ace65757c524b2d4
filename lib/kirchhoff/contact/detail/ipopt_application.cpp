#include "kirchhoff/contact/detail/ipopt_application.hpp"

#include <dlfcn.h>

#include <mutex>
#include <stdexcept>
#include <string>

namespace kirchhoff::detail {
namespace {

using Factory = Ipopt::IpoptApplication* (*)();

// Opened once per process (dlopen is thread-safe; call_once keeps one handle and one error).
Factory ipopt_factory() {
  static std::once_flag once;
  static Factory factory = nullptr;
  static std::string error;
  std::call_once(once, [] {
    // RTLD_GLOBAL: MUMPS and Ipopt's own plugins resolve against what they load.
    void* library = ::dlopen(KIRCHHOFF_IPOPT_LIBRARY, RTLD_NOW | RTLD_GLOBAL);
    if (!library) {
      error = ::dlerror();
      return;
    }
    factory = reinterpret_cast<Factory>(::dlsym(library, "IpoptApplicationFactory"));
    if (!factory) error = ::dlerror();
  });
  if (!factory)
    throw std::runtime_error(std::string("cannot load Ipopt (") + KIRCHHOFF_IPOPT_LIBRARY + "): " + error);
  return factory;
}

}  // namespace

Ipopt::SmartPtr<Ipopt::IpoptApplication> make_ipopt_application() { return ipopt_factory()(); }

}  // namespace kirchhoff::detail
