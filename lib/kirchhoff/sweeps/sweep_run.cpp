#include "kirchhoff/sweeps/sweep_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "kirchhoff/analysis/discrete_stability.hpp"
#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/contact/contact.hpp"
#include "kirchhoff/equations/integrator.hpp"
#include "kirchhoff/jobs/case_continue.hpp"
#include "kirchhoff/jobs/case_equilibria.hpp"
#include "kirchhoff/jobs/case_solve.hpp"
#include "kirchhoff/jobs/continue_outputs.hpp"
#include "kirchhoff/jobs/equilibria.hpp"
#include "kirchhoff/sweeps/plectoneme_sweep.hpp"

namespace kirchhoff {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A number as JSON holds it (null for NaN and inf, which JSON cannot).
json number(double x) { return std::isfinite(x) ? json(x) : json(); }

json overrides_json(const ParameterOverrides& values) {
  json out = json::object();
  for (const auto& [name, value] : values) out[name] = number(value);
  return out;
}

json contacts_json(const ShootingProblem& problem, const Solution& sol) {
  json out = json::array();
  for (const auto& c : report_contacts(problem, sol))
    out.push_back({{"obstacle", c.obstacle},
                   {"obstacle_name", c.obstacle_name},
                   {"extended", c.extended},
                   {"s", number(c.s)},
                   {"s_end", number(c.s_end)},
                   {"force", number(c.force)},
                   {"force_end", number(c.force_end)}});
  return out;
}

json derived_json(const Solution& sol) {
  json out = json::object();
  for (const auto& [name, value] : sol.derived) out[name] = number(value);
  return out;
}

json stability_index(const StabilityReport& s) { return s.index ? json(*s.index) : json(); }
// Beside the index (a straight column at P = pi^2 is index 0 with one zero mode): null with it.
json zero_modes(const StabilityReport& s) { return s.index ? json(s.zero_modes) : json(); }

// Writes `text` to `path` through a temporary file renamed over it (atomic on POSIX).
void write_atomically(const fs::path& path, const std::string& text) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(tmp.string() + ": cannot write");
    out << text;
    out.flush();
    if (!out) throw std::runtime_error(tmp.string() + ": cannot write");
  }
  fs::rename(tmp, path);
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot read");
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

// A solve job: solve_case as `kirchhoff solve` does (the solution, its checks and its stability
// index; the index's independent check is not reported here, but where the conjugate points leave
// the index undefined it is made, and decides it as in `solve`), then its energy.
void run_solve(const SweepJob& job, const Case& c, const fs::path& folder, json* result) {
  CaseSolveOptions options;
  options.direct = job.direct;
  options.stability_check = false;
  const CaseSolve solved = solve_case(c, options);
  (*result)["method"] = solved.path.method;
  if (!solved.failure.empty()) {
    (*result)["status"] = solved.failure;
    (*result)["reason"] = solved.message;
    return;
  }
  if (!solved.converged()) {  // Newton's verdict, or the profile's checks' (verification.hpp)
    (*result)["status"] = to_string(solved.summary().status);
    (*result)["reason"] = solved.summary().message;
    return;
  }
  const ShootingProblem& problem = *solved.solved.problem;
  const Solution& sol = *solved.solution;
  const StabilityReport stability =
      with_discretised_index_where_undefined(*solved.stability, problem, sol.result.x, true);
  const std::string state = contact_state(problem.obstacles(sol.result.parameters), sol.contacts);
  (*result)["status"] = "ok";
  (*result)["reason"] = "";
  (*result)["contact_state"] = state;
  (*result)["stable_states"] = stability.stable() ? state : "";
  (*result)["stability_index"] = stability_index(stability);
  (*result)["zero_modes"] = zero_modes(stability);
  (*result)["stability_reason"] = stability.reason;
  (*result)["stability_method"] = stability.method;
  (*result)["equilibria"] = 1;
  (*result)["energy"] = number(total_potential_energy(problem, sol.result.x));
  (*result)["derived"] = derived_json(sol);
  (*result)["contacts"] = contacts_json(problem, sol);
  (*result)["iterations"] = sol.result.summary.iterations;
  (*result)["residual"] = number(sol.result.summary.residual_norm);
  (*result)["H_spread"] = number(sol.invariants.H.spread);
  if (job.profiles) {
    write_profile_csv((folder / "profile.csv").string(), problem.equations(sol.result.parameters)->model(), sol.profile,
                      problem.definition().kind);
    (*result)["files"] = json::array({"profile.csv"});
  }
}

// An equilibria job: find_case_equilibria as `kirchhoff equilibria` does; the row describes the
// lowest-energy equilibrium, and lists every contact state found and the stable ones.
void run_equilibria(const SweepJob& job, const Case& c, const fs::path& folder, json* result) {
  EquilibriaOptions options;
  options.max_equilibria = job.max_equilibria;
  options.max_seconds = job.max_seconds;
  const EquilibriaSearch search = find_case_equilibria(c, c.samples, options);
  (*result)["stopped_because"] = search.stopped_because;
  (*result)["newton_runs"] = search.newton_runs;
  (*result)["equilibria"] = static_cast<int>(search.equilibria.size());
  if (search.equilibria.empty()) {
    (*result)["status"] = "none_found";
    (*result)["reason"] = "no equilibrium found (" + search.stopped_because + ")";
    return;
  }
  std::vector<std::string> states, stable_states;
  json list = json::array();
  json files = json::array();
  for (std::size_t i = 0; i < search.equilibria.size(); ++i) {
    const Equilibrium& e = search.equilibria[i];
    const std::string state = contact_state(e.problem->obstacles(e.solution.result.parameters), e.solution.contacts);
    if (std::find(states.begin(), states.end(), state) == states.end()) states.push_back(state);
    if (e.stability.stable() && std::find(stable_states.begin(), stable_states.end(), state) == stable_states.end())
      stable_states.push_back(state);
    list.push_back({{"rank", i + 1},
                    {"energy", number(e.energy)},
                    {"contact_state", state},
                    {"stability_index", stability_index(e.stability)},
                    {"zero_modes", zero_modes(e.stability)},
                    {"stability_reason", e.stability.reason},
                    {"derived", derived_json(e.solution)},
                    {"contacts", contacts_json(*e.problem, e.solution)},
                    {"found_by", e.found_by}});
    if (job.profiles) {
      const std::string name = "equilibrium_" + std::to_string(i + 1) + ".csv";
      write_profile_csv((folder / name).string(), e.problem->equations(e.solution.result.parameters)->model(),
                        e.solution.profile, e.problem->definition().kind);
      files.push_back(name);
    }
  }
  auto joined = [](const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : "+") + x;
    return s;
  };
  const Equilibrium& lowest = search.equilibria.front();
  (*result)["status"] = "ok";
  (*result)["reason"] = "";
  (*result)["contact_state"] = joined(states);
  (*result)["stable_states"] = joined(stable_states);
  (*result)["stability_index"] = stability_index(lowest.stability);
  (*result)["zero_modes"] = zero_modes(lowest.stability);
  (*result)["energy"] = number(lowest.energy);
  (*result)["derived"] = derived_json(lowest.solution);
  (*result)["list"] = std::move(list);
  if (job.profiles) (*result)["files"] = std::move(files);
}

// A continue job: continue_case as `kirchhoff continue` does, the branch into branch.csv. The row
// says how the run ended (ok: normally, at its target, a bound, its point budget...).
void run_continue(const SweepJob& job, const Case& c, const fs::path& folder, json* result) {
  ContinueRequest request;
  request.parameter = job.param;
  if (!std::isnan(job.to)) request.target = job.to;  // (NaN: the job gives no `to`)
  request.max_points = job.max_points;
  request.initial_step = job.step;
  request.min_step = job.min_step;
  request.max_step = job.max_step;
  request.detect_branch_points = job.branch_points;
  request.compute_stability = job.stability;
  request.max_seconds = job.max_seconds;
  request.set_parameters = job.overrides();
  if (const std::string why = request.validate(c); !why.empty()) {
    (*result)["status"] = "bad_input";
    (*result)["reason"] = why;
    return;
  }
  BranchCsvSink csv(folder / "branch.csv");
  const ContinueRunResult run = continue_case(c, request, {&csv});
  (*result)["status"] = run.ok ? "ok" : run.status;
  (*result)["reason"] = run.ok ? "" : run.message;
  (*result)["stopped_because"] = run.status;
  (*result)["message"] = run.message;
  (*result)["points"] = run.points;
  (*result)["contact_changes"] = run.contact_changes;
  (*result)["files"] = json::array({"branch.csv"});
}

// A plectonemes job: sweep_plectonemes (`kirchhoff plectonemes`) for the job's slenderness, the
// thicker one first with from_ply; its CSVs into the job's folder, its progress lines (as the
// command's, every 50 points) to `progress` after the job's id.
void run_plectonemes(const SweepJob& job, const fs::path& folder, const SweepProgress& progress, json* result) {
  auto value = [&job](const std::string& name) {
    for (const auto& [n, x] : job.values)
      if (n == name) return x;
    return 0.0;  // load_sweep requires both
  };
  PlectonemesArguments args;
  args.case_path = job.case_path;
  args.out_dir = folder.string();
  if (progress) {
    args.progress = [id = job.id, progress](const std::string& line) {
      progress(id + ": " + line.substr(std::min(line.find_first_not_of(' '), line.size())));
    };
  }
  args.hard_from = job.hard_from;
  args.slenderness = {value("slenderness")};
  args.turns = {value("turns")};
  args.from_ply = {};
  if (job.from_ply > 0) {
    args.slenderness.insert(args.slenderness.begin(), job.from_ply);
    args.turns.insert(args.turns.begin(), job.from_ply_turns);
    args.from_ply = {value("slenderness")};
  }
  std::ostringstream report;
  PlectonemeSweep sweep;
  try {
    sweep = sweep_plectonemes(args, report);
  } catch (const CaseError& e) {
    (*result)["status"] = "bad_input";
    (*result)["reason"] = e.what();
    return;
  } catch (const std::runtime_error& e) {
    (*result)["status"] = "branch_failed";
    (*result)["reason"] = e.what();
    return;
  }
  json branches = json::array();
  json files = json::array();
  for (const auto& b : sweep.branches) {
    json last = json::object();
    for (const auto& [name, x] : b.summary.last) last[name] = number(x);
    branches.push_back({{"slenderness", b.slenderness}, {"stop", b.summary.stop}, {"last_ply_point", last},
                        {"hard_ply_stop", b.summary.hard_ply_stop}});
    for (const auto& f : {b.barrier_csv, b.ply_csv})
      if (!f.empty()) files.push_back(fs::path(f).filename().string());
  }
  (*result)["status"] = "ok";
  (*result)["reason"] = "";
  (*result)["points"] = sweep.points;
  // The index's quantities (T_ext, helix angle, ...) are those of the job's own slenderness: the
  // last branch (a from_ply job computes the thicker one first), at its last ply point.
  if (!branches.empty()) (*result)["derived"] = branches.back()["last_ply_point"];
  (*result)["branches"] = std::move(branches);
  (*result)["files"] = std::move(files);
}

// CSV cell: quoted when it holds a comma, a quote or a line break.
std::string csv_cell(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char ch : s) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

std::string cell(const json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) return v.get<std::string>();
  return v.dump();  // numbers: the shortest text that reads back to the same double
}

}  // namespace

std::string contact_state(const std::vector<Obstacle>& obstacles, const std::vector<PointContact>& contacts) {
  if (contacts.empty()) return "none";
  if (contacts.size() == 1) {
    const PointContact& c = contacts.front();
    if (!c.extended) return "point";
    const bool flat = c.obstacle >= 0 && c.obstacle < static_cast<int>(obstacles.size()) &&
                      obstacles[static_cast<std::size_t>(c.obstacle)].is_flat();
    return flat ? "flat" : "wrap";
  }
  if (contacts.size() == 2 && !contacts[0].extended && !contacts[1].extended &&
      contacts[0].obstacle == contacts[1].obstacle)
    return "hanging_fold";
  return "several";
}

JobOutcome run_sweep_job(const SweepJob& job, const std::string& dir, const SweepProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  const fs::path jobs = fs::path(dir) / "jobs";
  const fs::path partial = jobs / ("." + job.id + ".partial");
  const fs::path final_folder = jobs / job.id;
  fs::remove_all(partial);
  fs::create_directories(partial);
  json result;
  result["job"] = job.id;
  result["kind"] = to_string(job.kind);
  result["case"] = job.case_name;
  result["parameters"] = overrides_json(job.values);
  result["set"] = overrides_json(job.set);
  result["fingerprint"] = job.fingerprint();
  try {
    if (job.kind == SweepJobKind::Plectonemes) {
      run_plectonemes(job, partial, progress, &result);  // the sweep loads the case itself
    } else {
      Case c = load_case(job.case_path, job.overrides(), "", job.solver);
      if (job.kind == SweepJobKind::Solve) limit_wall_clock(c.definition.options, job.max_seconds);
      if (job.kind == SweepJobKind::Solve) run_solve(job, c, partial, &result);
      else if (job.kind == SweepJobKind::Equilibria) run_equilibria(job, c, partial, &result);
      else run_continue(job, c, partial, &result);
    }
  } catch (const CaseError& e) {
    result["status"] = "bad_input";
    result["reason"] = e.what();
  } catch (const InfeasibleContact& e) {
    result["status"] = "infeasible";
    result["reason"] = e.what();
  } catch (const IntegrationError& e) {
    result["status"] = "integration_failed";
    result["reason"] = e.what();
  } catch (const std::exception& e) {
    result["status"] = "error";
    result["reason"] = e.what();
  }
  write_atomically(partial / "result.json", result.dump(2) + "\n");
  fs::remove_all(final_folder);  // only a folder left by a job id reused by hand
  fs::rename(partial, final_folder);
  JobOutcome outcome;
  outcome.status = result.value("status", "error");
  outcome.reason = result.value("reason", "");
  outcome.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return outcome;
}

std::vector<int> prepare_sweep_folder(const SweepSpec& spec, const std::string& dir, bool resume) {
  const fs::path jobs = fs::path(dir) / "jobs";
  std::error_code ec;
  fs::create_directories(jobs, ec);
  if (ec) throw SweepError(dir + ": cannot create the output folder (" + ec.message() + ")");
  std::set<std::string> ids;
  for (const auto& job : spec.jobs) ids.insert(job.id);
  bool any = false;
  for (const auto& entry : fs::directory_iterator(jobs)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name[0] == '.') {
      fs::remove_all(entry.path());  // a partial job folder: its job runs again
      continue;
    }
    any = true;
  }
  if (any && !resume)
    throw SweepError(dir + ": holds the results of a sweep already (jobs/); --resume goes on with it, or choose another --out");
  std::vector<int> to_run;
  for (const auto& job : spec.jobs) {
    const fs::path result = jobs / job.id / "result.json";
    if (!fs::exists(result)) {
      fs::remove_all(jobs / job.id);
      to_run.push_back(job.order);
      continue;
    }
    json j;
    try {
      j = json::parse(read_file(result));
    } catch (const std::exception& e) {
      throw SweepError(result.string() + ": not a job result (" + e.what() + ")");
    }
    if (j.value("fingerprint", "") != job.fingerprint())
      throw SweepError(result.string() + ": computed for another job than " + spec.path + " now gives '" + job.id +
                       "' (was: " + j.value("fingerprint", "?") + "; now: " + job.fingerprint() +
                       "): the sweep file changed; choose another --out");
  }
  return to_run;
}

void record_job_time(const std::string& dir, const std::string& id, double seconds, int rank) {
  const fs::path path = fs::path(dir) / "times.csv";
  const bool fresh = !fs::exists(path);
  std::FILE* f = std::fopen(path.string().c_str(), "a");
  if (!f) return;  // times are informative; a job's result does not depend on them
  if (fresh) std::fputs("job,seconds,rank\n", f);
  std::fprintf(f, "%s,%.3f,%d\n", id.c_str(), seconds, rank);
  std::fclose(f);
}

SweepIndex write_sweep_index(const SweepSpec& spec, const std::string& dir) {
  SweepIndex index;
  auto column = [&index](const std::string& name, bool numeric) {
    index.columns.push_back(name);
    index.numeric.push_back(numeric);
  };
  column("job", false);
  column("kind", false);
  for (const auto& p : spec.parameter_columns) column(p, true);
  for (const char* name : {"status", "reason", "contact_state", "stable_states"}) column(name, false);
  for (const char* name : {"stability_index", "zero_modes", "equilibria", "energy"}) column(name, true);
  // A derived quantity named like a column before it (a parameter P and the derived P) is
  // derived_<name>.
  for (const auto& d : spec.derived_columns)
    column(std::find(index.columns.begin(), index.columns.end(), d) == index.columns.end() ? d : "derived_" + d, true);

  const fs::path jobs = fs::path(dir) / "jobs";
  for (const auto& job : spec.jobs) {
    std::vector<std::string> row;
    row.push_back(job.id);
    row.push_back(to_string(job.kind));
    for (const auto& p : spec.parameter_columns) {
      const auto it =
          std::find_if(job.values.begin(), job.values.end(), [&p](const auto& v) { return v.first == p; });
      row.push_back(it == job.values.end() ? "" : cell(number(it->second)));
    }
    json j;
    const fs::path result = jobs / job.id / "result.json";
    if (fs::exists(result)) j = json::parse(read_file(result));
    else j = {{"status", "not_run"}};
    for (const char* name : {"status", "reason", "contact_state", "stable_states", "stability_index", "zero_modes",
                             "equilibria", "energy"})
      row.push_back(j.contains(name) ? cell(j[name]) : "");
    for (const auto& d : spec.derived_columns) {
      const json* derived = j.contains("derived") ? &j["derived"] : nullptr;
      row.push_back(derived && derived->contains(d) ? cell((*derived)[d]) : "");
    }
    index.rows.push_back(std::move(row));
  }
  std::ostringstream csv;
  for (std::size_t k = 0; k < index.columns.size(); ++k) csv << (k ? "," : "") << csv_cell(index.columns[k]);
  csv << "\n";
  for (const auto& row : index.rows) {
    for (std::size_t k = 0; k < row.size(); ++k) csv << (k ? "," : "") << csv_cell(row[k]);
    csv << "\n";
  }
  write_atomically(fs::path(dir) / "index.csv", csv.str());
  return index;
}

std::string describe_job_end(const SweepJob& job, const JobOutcome& outcome, int done, int total) {
  std::ostringstream os;
  os << "[" << done << "/" << total << "] " << job.id;
  for (const auto& [name, value] : job.values) os << " " << name << "=" << value;
  os << ": " << outcome.status;
  if (!outcome.reason.empty()) os << " (" << outcome.reason.substr(0, 200) << ")";
  os.precision(3);
  os << " [" << outcome.seconds << " s]";
  return os.str();
}

SweepSummary run_sweep(const SweepSpec& spec, const SweepRunOptions& options) {
  // K copies of the serial sweep started by an MPI launcher would each run the whole sweep into
  // the same folder (the CLI built with MPI shares the jobs out instead: sweep_mpi.hpp).
  if (const int launched = launcher_process_count(); launched > 1)
    throw SweepError("started as one of " + std::to_string(launched) +
                     " MPI processes, but this is the serial sweep: each would run the whole sweep into the same "
                     "folder. Run the CLI's sweep built with MPI (libopenmpi-dev) under mpirun, or run it without");
  const std::vector<int> to_run = prepare_sweep_folder(spec, options.out_dir, options.resume);
  SweepSummary summary;
  summary.jobs = static_cast<int>(spec.jobs.size());
  summary.skipped = summary.jobs - static_cast<int>(to_run.size());
  int done = summary.skipped;
  for (int k : to_run) {
    const SweepJob& job = spec.jobs[static_cast<std::size_t>(k)];
    const JobOutcome outcome = run_sweep_job(job, options.out_dir, options.progress);
    record_job_time(options.out_dir, job.id, outcome.seconds, 0);
    ++summary.ran;
    if (options.progress) options.progress(describe_job_end(job, outcome, ++done, summary.jobs));
  }
  summary.index = write_sweep_index(spec, options.out_dir);
  const auto status = std::find(summary.index.columns.begin(), summary.index.columns.end(), "status") -
                      summary.index.columns.begin();
  for (const auto& row : summary.index.rows)
    if (row[static_cast<std::size_t>(status)] != "ok") ++summary.failed;
  return summary;
}

int launcher_process_count() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "SLURM_STEP_NUM_TASKS"})
    if (const char* v = std::getenv(name); v && *v) {
      const int n = std::atoi(v);
      if (n > 0) return n;
    }
  return 0;
}

}  // namespace kirchhoff
