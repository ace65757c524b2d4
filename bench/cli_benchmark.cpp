// What a user loses by running a branch through the CLI instead of the library: the README's Euler
// column (`kirchhoff continue cases/euler_column.toml --param P --to 12 --set P=1 --set
// theta_guess=0 --switch-at-bp 1 --event theta0=3 --max-step 1`: the straight column to its branch
// point, then the buckled branch to theta0 = 3) run
//   1. in this process with continue_case and no outputs (the mathematics alone),
//   2. in this process with the CLI's outputs: the branch CSV and the state file (checkpointed),
//   3. as the CLI itself, a child process (process start, case loading, terminal lines included),
//   4. as 2, in a child process of its own: this benchmark started again with --library-once,
//      which runs 2 once and exits,
// alternately, `--reps` times each. Times are CPU time (this process's for 1-2, the child's user +
// system time for 3-4, from wait4) beside the wall time; the ratios are points per second of 2, 3
// and 4 against 1, from medians. Issue 24's goal: the CLI within 20 % of the library (ratio >= 0.8).
// 4 tells what any process pays to run the library once - starting, loading its libraries,
// faulting in its pages, caches and branch predictors cold - from what the CLI adds to it (3
// against 4).
//
//   cli_benchmark [--reps N] [--checkpoint SECONDS] [--stability on|off] [--out DIR]
//
// --stability off runs every variant without the stability index (the CLI's --no-stability).
// --out DIR: where the CSVs go (default: a fresh directory under the system's temporary one;
// put it on the file system you want measured).
#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "kirchhoff/jobs/case_continue.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/continue_outputs.hpp"
#include "kirchhoff/jobs/process_memory.hpp"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using namespace kirchhoff;

struct Options {
  bool library_once = false;  // variant 4's child: run the library with outputs once, then exit
  int reps = 5;
  double checkpoint = 1.0;  // the CLI's default --checkpoint
  bool stability = true;    // the CLI's default
  fs::path out;
};

struct Timing {
  double cpu_s = 0.0;
  double wall_s = 0.0;
  int points = 0;
};

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double seconds(const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); }

std::string case_path() { return std::string(KIRCHHOFF_CASES_DIR) + "/euler_column.toml"; }

// The request the CLI builds from the arguments above (apps/continue_command.cpp).
ContinueRequest euler_request(const Options& o) {
  ContinueRequest r;
  r.parameter = "P";
  r.target = 12.0;
  r.max_step = 1.0;
  r.switch_at_bp = 1;
  r.compute_stability = o.stability;
  r.events.push_back({"theta0", 3.0, true, ""});
  r.set_parameters = {{"P", 1.0}, {"theta_guess", 0.0}};
  return r;
}

Case euler_case(const ContinueRequest& r) { return load_case(case_path(), r.set_parameters); }

// 1 and 2: the library, with or without the CLI's two file outputs. Case loading is included, as
// the CLI's run includes it.
Timing run_library(const Options& o, bool with_outputs, const fs::path& csv) {
  const double cpu0 = process_cpu_seconds();
  const auto wall0 = std::chrono::steady_clock::now();
  const ContinueRequest request = euler_request(o);
  const Case c = euler_case(request);
  std::vector<ContinueSink*> sinks;
  std::unique_ptr<BranchCsvSink> branch;
  std::unique_ptr<StateFileSink> state;
  if (with_outputs) {
    branch = std::make_unique<BranchCsvSink>(csv);
    state = std::make_unique<StateFileSink>(
        fs::path(csv.string() + ".state.json"),
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(o.checkpoint)));
    sinks = {branch.get(), state.get()};
  }
  const ContinueRunResult result = continue_case(c, request, sinks);
  if (!result.ok) throw std::runtime_error("the library's run did not end normally: " + result.message);
  Timing t;
  t.cpu_s = process_cpu_seconds() - cpu0;
  t.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  t.points = result.points;
  return t;
}

int csv_rows(const fs::path& csv) {
  std::ifstream in(csv);
  int lines = 0;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') ++lines;
  return std::max(0, lines - 1);  // the header
}

// `args` as a child process, its terminal output discarded: its CPU and wall time, and the CSV
// rows it wrote to `csv`.
Timing run_child(std::vector<std::string> args, const fs::path& csv) {
  fs::remove(csv);
  fs::remove(csv.string() + ".state.json");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  const auto wall0 = std::chrono::steady_clock::now();
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) throw std::runtime_error("cannot start " + args[0] + ": " + std::strerror(spawned));
  int status = 0;
  rusage usage{};
  if (wait4(pid, &status, 0, &usage) != pid) throw std::runtime_error("wait4 failed");
  Timing t;
  t.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) throw std::runtime_error(args[0] + "'s run failed");
  t.cpu_s = seconds(usage.ru_utime) + seconds(usage.ru_stime);
  t.points = csv_rows(csv);
  return t;
}

// 3: the CLI.
Timing run_cli(const Options& o, const fs::path& csv) {
  std::vector<std::string> args = {KIRCHHOFF_CLI, "continue", case_path(), "--param", "P", "--to", "12",
                                   "--set", "P=1", "--set", "theta_guess=0", "--switch-at-bp", "1",
                                   "--event", "theta0=3", "--max-step", "1", "--checkpoint",
                                   std::to_string(o.checkpoint), "--out", csv.string()};
  if (!o.stability) args.push_back("--no-stability");
  return run_child(args, csv);
}

// 4: this benchmark, started again to run 2 once (`self`: its own path).
Timing run_library_process(const Options& o, const std::string& self, const fs::path& csv) {
  std::vector<std::string> args = {self, "--library-once", "--out", csv.parent_path().string(),
                                   "--checkpoint", std::to_string(o.checkpoint), "--stability",
                                   o.stability ? "on" : "off"};
  return run_child(args, csv);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Series {
  const char* name;
  std::vector<Timing> runs;
  double cpu() const {
    std::vector<double> v;
    for (const auto& r : runs) v.push_back(r.cpu_s);
    return median(v);
  }
  double wall() const {
    std::vector<double> v;
    for (const auto& r : runs) v.push_back(r.wall_s);
    return median(v);
  }
  int points() const { return runs.empty() ? 0 : runs.front().points; }
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      return argv[++i];
    };
    if (a == "--library-once") o.library_once = true;
    else if (a == "--reps") o.reps = std::stoi(value());
    else if (a == "--checkpoint") o.checkpoint = std::stod(value());
    else if (a == "--stability") o.stability = value() != "off";
    else if (a == "--out") o.out = value();
    else throw std::invalid_argument("unknown argument '" + a + "'");
  }
  if (o.reps < 1) throw std::invalid_argument("--reps must be >= 1");
  if (o.out.empty()) o.out = fs::temp_directory_path() / ("kirchhoff_cli_benchmark_" + std::to_string(getpid()));
  fs::create_directories(o.out);
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  kirchhoff::keep_freed_memory_for_reuse();  // as the CLI's main, so that the two run alike
  try {
    const Options o = parse(argc, argv);
    if (o.library_once) {
      run_library(o, true, o.out / "process.csv");
      return 0;
    }
    Series library{"library, no outputs", {}}, outputs{"library + CSV + state file", {}}, cli{"CLI (child process)", {}},
        process{"library + outputs, own process", {}};
    // Alternating, each round in another order, so that a load on the machine and the order of
    // the runs (caches, a page cache warmed by the one before) hit all four alike.
    const std::string self = fs::read_symlink("/proc/self/exe").string();  // variant 4's program
    const std::function<void()> variants[] = {
        [&] { library.runs.push_back(run_library(o, false, {})); },
        [&] { outputs.runs.push_back(run_library(o, true, o.out / "library.csv")); },
        [&] { cli.runs.push_back(run_cli(o, o.out / "cli.csv")); },
        [&] { process.runs.push_back(run_library_process(o, self, o.out / "process.csv")); }};
    constexpr int kVariants = 4;
    for (int r = 0; r < o.reps; ++r)
      for (int k = 0; k < kVariants; ++k) variants[(r + k) % kVariants]();
    std::printf("Euler column, the README's continue command (branch point, switch, event theta0 = 3), stability %s,\n"
                "--checkpoint %g s, outputs in %s; medians of %d alternating runs.\n\n",
                o.stability ? "on" : "off", o.checkpoint, o.out.c_str(), o.reps);
    std::printf("%-30s %7s %9s %9s %11s %11s\n", "run", "points", "cpu_ms", "wall_ms", "points/s", "wall pts/s");
    for (const Series* s : {&library, &outputs, &process, &cli})
      std::printf("%-30s %7d %9.1f %9.1f %11.0f %11.0f\n", s->name, s->points(), 1e3 * s->cpu(), 1e3 * s->wall(),
                  s->points() / s->cpu(), s->points() / s->wall());
    if (cli.points() != library.points() || outputs.points() != library.points() || process.points() != library.points())
      std::printf("\nwarning: the runs wrote different numbers of points\n");
    std::printf("\nRatios (points/s against the library without outputs; goal for the CLI >= 0.8):\n");
    std::printf("  library + outputs                 cpu %.3f  wall %.3f\n", library.cpu() / outputs.cpu(), library.wall() / outputs.wall());
    std::printf("  library + outputs, own process    cpu %.3f  wall %.3f\n", library.cpu() / process.cpu(),
                library.wall() / process.wall());
    std::printf("  CLI                               cpu %.3f  wall %.3f\n", library.cpu() / cli.cpu(), library.wall() / cli.wall());
    std::printf("The CLI against the library + outputs in a process of its own (what the CLI adds to starting a\n"
                "process that runs the library once): cpu %.3f  wall %.3f\n", process.cpu() / cli.cpu(),
                process.wall() / cli.wall());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
