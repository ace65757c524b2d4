#include "kirchhoff/jobs/run_plan.hpp"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace kirchhoff {
namespace {

// A run started from another case's run: the names its state brings that this case lacks, said
// as such (load_case would call them a --set the user never typed).
void refuse_foreign_parameters(const RunStart& start, const RunPlanInputs& in) {
  const Case plain = load_case(in.case_path, {}, in.phase_condition);
  for (size_t k = 0; k < start.parameters.size(); ++k)
    if (!plain.file_parameters.contains(start.parameters[k].first))
      throw CaseError(in.start_from + ": its run's parameter '" + start.parameters[k].first + "' (" +
                      start.sources[k] + ") is not a parameter of " + in.case_path);
}

// Whether the run resumes: a state file to resume from, or none and nothing to lose (see
// RunPlanInputs::csv_path), said in a note.
bool resumes(const RunPlanInputs& in, std::vector<std::string>* notes) {
  if (in.state_path.empty())
    throw CaseError("resume needs state=PATH, the state file of the run to resume");
  if (std::filesystem::exists(in.state_path)) return true;
  if (in.csv_path.empty())
    throw CaseError("cannot resume: no state file " + in.state_path.string() +
                    " (a run saves it after its first point)");
  if (const int rows = branch_csv_rows(in.csv_path); rows > 1)
    throw CaseError("cannot resume: " + in.csv_path.string() + " has " + std::to_string(rows) +
                    " rows but there is no state file " + in.state_path.string() +
                    " (a run saves it after its first point, so it was removed or the rows come from another "
                    "run); run again without --resume to compute the branch from its start");
  notes->push_back("resume: no state file " + in.state_path.string() +
                   ": the run was stopped before its first point was saved, so it starts from the beginning");
  return false;
}

// A path as the identity holds it: canonical where it exists, so that "cases/../cases/x.toml"
// and "cases/x.toml" name the same run.
std::string canonical_text(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(path, ec);
  return (ec ? std::filesystem::path(path) : canonical).string();
}

// A state file read: what cannot be read (a directory, a truncated file) is bad input, said as a
// CaseError by both front ends; CaseError and std::invalid_argument (refusals) pass as they are.
template <class Read>
auto reading_state(const std::string& path, Read&& read) {
  try {
    return read();
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const CaseError&) {
    throw;  // read, and refused with its reason (a run with other arguments, say)
  } catch (const std::exception& e) {
    throw CaseError(path + ": the state file cannot be read: " + e.what());
  }
}

}  // namespace

std::string run_identity(const RunPlanInputs& in, const ContinueRequest& r) {
  std::ifstream file(in.case_path, std::ios::binary);
  std::uint64_t hash = 14695981039346656037ull;  // FNV-1a of the case file's bytes
  for (char ch; file.get(ch);) hash = (hash ^ static_cast<unsigned char>(ch)) * 1099511628211ull;
  std::ostringstream o;
  o << std::setprecision(17) << "case=" << canonical_text(in.case_path) << " case_hash=" << std::hex << hash
    << std::dec << " param=" << r.parameter;
  for (const auto& [name, value] : in.overrides) o << " set=" << name << "=" << value;
  for (const auto& [key, value] : in.solver) o << " solver=" << key << "=" << value;
  o << " phase=" << (in.phase_condition.empty() ? "none" : in.phase_condition) << " to=";
  if (!r.target)
    o << "none";
  else
    o << *r.target;
  o << " direction=" << r.direction << " step=" << r.initial_step << " min_step=" << r.min_step
    << " max_step=" << r.max_step << " max_points=" << r.max_points << " switch_at_bp=" << r.switch_at_bp
    << " side=" << r.switch_side << " branch_points=" << r.detect_branch_points
    << " stability=" << r.compute_stability << " samples=" << r.samples;
  for (const auto& e : r.events) o << (e.stop ? " event=" : " record=") << e.quantity << "=" << e.value;
  if (!in.start_from.empty()) o << " start_from=" << canonical_text(in.start_from);
  o << " seed=" << (r.seed.ipopt ? "ipopt" : "guess");
  if (r.seed.ipopt) o << " seed_segments=" << r.seed.segments << " seed_amplitude=" << r.seed.amplitude;
  return o.str();
}

int branch_csv_rows(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // the header
  int count = 0;
  while (std::getline(in, line))
    if (!line.empty()) ++count;
  return count;
}

RunPlan plan_run(const RunPlanInputs& in, ContinueRequest* request, const Case* loaded) {
  // Refused before any file is read (validate says the same once the case is loaded).
  if (request->deflate && (in.resume || !in.start_from.empty())) throw CaseError(kDeflateRefusal);
  if (!in.start_from.empty() && request->seed.ipopt) throw CaseError("--start-from does not combine with --seed");
  RunPlan plan;
  if (request->identity.empty()) request->identity = run_identity(in, *request);
  ParameterOverrides overrides = in.overrides;
  bool reload = loaded == nullptr;
  if (const bool resuming = in.resume && resumes(in, &plan.notes); resuming) {
    const std::string path = in.state_path.string();
    request->resume = reading_state(path, [&] { return resumable_state(path, request->identity); });
    // A run started from another one keeps the values it started with (the other run's, which
    // its arguments do not hold).
    if (request->resume->has_set_parameters) overrides = request->resume->set_parameters, reload = true;
  } else if (!in.start_from.empty()) {
    plan.start = reading_state(in.start_from, [&] { return plan_start_from(in.start_from, in.start_param, overrides); });
    refuse_foreign_parameters(*plan.start, in);
    overrides = plan.start->parameters, reload = true;
    request->start = plan.start->at;
    request->start_name = in.start_from;
  }
  plan.c = reload ? load_case(in.case_path, overrides, in.phase_condition, in.solver) : *loaded;
  request->set_parameters = overrides;
  if (std::string why = request->validate(plan.c); !why.empty()) throw CaseError(why);
  return plan;
}

}  // namespace kirchhoff
