#include "plectonemes_command.hpp"

#include <iomanip>
#include <iostream>

#include "kirchhoff/jobs/case_file.hpp"

namespace kirchhoff::cli {

int run_plectonemes(const PlectonemesArguments& arguments) {
  PlectonemesArguments args = arguments;
  args.progress = [](const std::string& line) { std::cerr << line << "\n"; };
  try {
    const PlectonemeSweep sweep = sweep_plectonemes(args, std::cout);
    std::cout << "sweep: " << sweep.points << " points in " << std::setprecision(4) << sweep.seconds << " s ("
              << sweep.points / sweep.seconds << " points/s)\n";
  } catch (const CaseError& e) {  // refused before anything ran
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace kirchhoff::cli
