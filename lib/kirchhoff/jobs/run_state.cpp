#include "kirchhoff/jobs/run_state.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "kirchhoff/jobs/case_file.hpp"

namespace kirchhoff {
namespace {

namespace fs = std::filesystem;

nlohmann::json to_json(const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); }
Eigen::VectorXd vector_from(const nlohmann::json& j) {
  const auto v = j.get<std::vector<double>>();
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

// The fields of a point a march resumes from (the rest is recomputed from x and the parameter).
// Doubles are written in their shortest round-trip form and read back to the same bits.
nlohmann::json point_json(const ContinuationPoint& p) {
  return {{"index", p.index},         {"parameter", p.parameter}, {"arclength", p.arclength},
          {"step", p.step},           {"x", to_json(p.x)},        {"tangent", to_json(p.tangent)},
          {"type", to_string(p.type)}, {"newton_iterations", p.newton_iterations}};
}

PointType point_type_from(const std::string& name);

ContinuationPoint point_from(const nlohmann::json& j) {
  ContinuationPoint p;
  p.index = j.at("index");
  p.parameter = j.at("parameter");
  p.arclength = j.at("arclength");
  p.step = j.at("step");
  p.x = vector_from(j.at("x"));
  p.tangent = vector_from(j.at("tangent"));
  p.type = point_type_from(j.at("type"));
  p.newton_iterations = j.value("newton_iterations", 0);
  return p;
}

PointType point_type_from(const std::string& name) {
  for (PointType t : {PointType::Start, PointType::Regular, PointType::Fold, PointType::BranchPoint, PointType::Event,
                      PointType::Endpoint, PointType::IndexChange})
    if (name == to_string(t)) return t;
  return PointType::Regular;
}

nlohmann::json contacts_json(const std::vector<PointContact>& contacts) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& c : contacts)
    j.push_back({{"obstacle", c.obstacle}, {"s", c.s}, {"force", c.force}, {"extended", c.extended},
                 {"s_end", c.s_end}, {"force_end", c.force_end}});
  return j;
}

std::vector<PointContact> contacts_from(const nlohmann::json& j) {
  std::vector<PointContact> out;
  for (const auto& c : j)
    out.push_back({c.at("obstacle").get<int>(), c.at("s").get<double>(), c.at("force").get<double>(),
                   c.at("extended").get<bool>(), c.at("s_end").get<double>(), c.at("force_end").get<double>()});
  return out;
}

nlohmann::json written_json(const WrittenPoint& w) {
  return {{"row", w.row},           {"branch", w.branch},
          {"phase_condition", w.phase_condition}, {"point", point_json(w.point)},
          {"contacts", contacts_json(w.contacts)}};
}

WrittenPoint written_from(const nlohmann::json& j) {
  WrittenPoint w;
  w.row = j.at("row");
  w.branch = j.at("branch");
  w.phase_condition = j.at("phase_condition");
  w.point = point_from(j.at("point"));
  w.contacts = contacts_from(j.at("contacts"));
  return w;
}

// The --set values of a run whose state file predates set_parameters, from its arguments line
// (" set=NAME=VALUE" each, as the user typed them: parsed again they are the same doubles).
std::vector<std::pair<std::string, double>> set_values_in(const std::string& arguments) {
  std::vector<std::pair<std::string, double>> out;
  std::istringstream words(arguments);
  for (std::string word; words >> word;)
    if (word.rfind("set=", 0) == 0) out.push_back(parse_override(word.substr(4)));
  return out;
}

}  // namespace

bool resumable(const ContinuationPoint& p) { return p.type == PointType::Start || p.type == PointType::Regular; }

void save_state(const std::filesystem::path& path, const RunState& s) {
  nlohmann::json j = {{"row", s.saved_row},             {"branch", s.branch},       {"phase_condition", s.phase_condition},
                      {"index", s.last.index},     {"parameter", s.last.parameter},
                      {"arclength", s.last.arclength}, {"step", s.last.step},
                      {"x", to_json(s.last.x)},    {"tangent", to_json(s.last.tangent)},
                      {"type", to_string(s.last.type)}};
  j["parameter_name"] = s.parameter_name;
  j["contacts"] = contacts_json(s.contacts);
  j["piece_segments"] = s.piece_segments;
  j["newton_iterations"] = s.last.newton_iterations;
  if (s.has_march) {
    nlohmann::json m = {{"previous_step", s.previous_step},
                        {"just_reported_branch_point", s.just_reported_branch_point},
                        {"branch_points_found", s.branch_points_found},
                        {"points", s.march_points},
                        {"refused_steps", s.refused_steps},
                        {"contact_bending_event", s.contact_bending_event},
                        {"leg_max_points", s.leg_max_points},
                        {"reported", s.reported},
                        {"first_leg", s.first_leg},
                        {"branch_points_before", s.branch_points_before}};
    if (s.before) m["before"] = point_json(*s.before);
    j["march"] = m;
  }
  if (s.written) j["written"] = written_json(*s.written);
  if (s.has_set_parameters) {
    // Pairs, not an object: the order is the order they were applied in.
    j["set_parameters"] = nlohmann::json::array();
    for (const auto& [name, value] : s.set_parameters) j["set_parameters"].push_back({name, value});
  }
  if (!s.arguments.empty()) j["arguments"] = s.arguments;
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << std::setprecision(17) << j.dump() << "\n";
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
  }
  fs::rename(tmp, path);  // atomic on POSIX: the state is always a complete point
}

void save_resume_point(const std::filesystem::path& path, const ContinuationPoint& p, RunState* state) {
  state->last = p;
  state->last.jacobian.reset();  // not needed to resume
  state->saved_row = state->row;
  save_state(path, *state);
}

RunState load_state(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot resume: no state file " + path.string());
  const nlohmann::json j = nlohmann::json::parse(in);
  RunState s;
  s.row = s.saved_row = j.at("row");
  s.branch = j.at("branch");
  s.phase_condition = j.at("phase_condition");
  s.parameter_name = j.value("parameter_name", "");
  s.last.index = j.at("index");
  s.last.parameter = j.at("parameter");
  s.last.arclength = j.at("arclength");
  s.last.step = j.at("step");
  s.last.x = vector_from(j.at("x"));
  s.last.tangent = vector_from(j.at("tangent"));
  s.last.type = point_type_from(j.at("type"));
  if (j.contains("contacts")) s.contacts = contacts_from(j.at("contacts"));
  if (j.contains("piece_segments")) s.piece_segments = j.at("piece_segments").get<std::vector<int>>();
  s.last.newton_iterations = j.value("newton_iterations", 0);
  if (j.contains("march")) {
    const nlohmann::json& m = j.at("march");
    s.has_march = true;
    if (m.contains("before")) s.before = point_from(m.at("before"));
    s.previous_step = m.at("previous_step");
    s.just_reported_branch_point = m.at("just_reported_branch_point");
    s.branch_points_found = m.at("branch_points_found");
    s.march_points = m.at("points");
    s.refused_steps = m.at("refused_steps");
    // (JSON has no NaN: a non-finite value is written as null.)
    const auto& bending = m.at("contact_bending_event");
    s.contact_bending_event = bending.is_null() ? NAN : bending.get<double>();
    s.leg_max_points = m.at("leg_max_points");
    s.reported = m.at("reported");
    s.first_leg = m.at("first_leg");
    // (0 in older files: contact runs could not stop at a branch point then.)
    s.branch_points_before = m.value("branch_points_before", 0);
  }
  if (j.contains("written")) s.written = written_from(j.at("written"));
  if (j.contains("set_parameters")) {
    s.has_set_parameters = true;
    for (const auto& pair : j.at("set_parameters"))
      s.set_parameters.emplace_back(pair.at(0).get<std::string>(), pair.at(1).get<double>());
  }
  s.arguments = j.value("arguments", "");
  return s;
}

namespace {

// The point a run started from `from` starts at: the last row it wrote. Where that row is also
// the last saved point (or an event whose new leg's start was saved after it, same parameter
// and rod, with the active set after the change) the saved point is taken, with its active set.
WrittenPoint start_point_of(const RunState& from) {
  if (from.written && from.written->row > from.saved_row) return *from.written;
  WrittenPoint saved{from.saved_row, from.branch, from.phase_condition, from.last, from.contacts};
  if (from.written) saved.point.type = from.written->point.type;  // the row's type (an event), for the message
  return saved;
}

bool names(const std::vector<std::pair<std::string, double>>& values, const std::string& name) {
  return std::any_of(values.begin(), values.end(), [&](const auto& v) { return v.first == name; });
}

}  // namespace

RunStart plan_start_from(const std::filesystem::path& state_path, const std::string& start_param,
                         const std::vector<std::pair<std::string, double>>& command_line) {
  const std::string file = state_path.string();
  RunState from;
  try {
    from = load_state(state_path);
  } catch (const std::exception& e) {
    throw std::invalid_argument("--start-from " + file + ": not a state file of `kirchhoff continue` (" + e.what() +
                                ")");
  }
  RunStart out;
  out.from_parameter = from.parameter_name.empty() ? start_param : from.parameter_name;
  if (out.from_parameter.empty())
    throw std::invalid_argument(file + " does not name its parameter: give it with --start-param");
  out.at = start_point_of(from);
  if (!from.written)
    out.notes.push_back(file + " predates the record of a run's last row: starting from its last saved point (row " +
                        std::to_string(from.saved_row) +
                        "), which is before the CSV's last row when that row is an endpoint, fold, branch point "
                        "or event");

  std::vector<std::pair<std::string, double>> kept = from.set_parameters;
  if (!from.has_set_parameters) {
    kept = set_values_in(from.arguments);
    if (from.arguments.empty())
      out.notes.push_back(file + " does not record its run's --set values: give them again with --set");
  }
  for (const auto& [name, value] : kept) {
    if (name == out.from_parameter || names(command_line, name)) continue;
    out.parameters.emplace_back(name, value);
    out.sources.push_back("kept from " + file);
  }
  out.parameters.emplace_back(out.from_parameter, out.at.point.parameter);
  out.sources.push_back("the point's, row " + std::to_string(out.at.row) + " of that run");
  for (const auto& [name, value] : command_line) {
    if (name == out.from_parameter) {
      std::ostringstream why;
      why << std::setprecision(15) << "--set " << name << " conflicts with --start-from " << file
          << ": its point is a solution at " << name << " = " << out.at.point.parameter
          << " only (continue in " << name << " to move it)";
      throw std::invalid_argument(why.str());
    }
    out.parameters.emplace_back(name, value);
    out.sources.push_back("--set");
  }
  return out;
}

MarchState march_state(const RunState& s) {
  MarchState m;
  m.current = s.last;
  m.before = s.before;
  m.previous_step = s.previous_step;
  m.just_reported_branch_point = s.just_reported_branch_point;
  m.branch_points_found = s.branch_points_found;
  m.points = s.march_points;
  m.refused_steps = s.refused_steps;
  return m;
}

void set_march_state(RunState* s, const MarchState& m) {
  s->last = m.current;
  s->last.jacobian.reset();
  s->before = m.before;
  if (s->before) s->before->jacobian.reset();
  s->previous_step = m.previous_step;
  s->just_reported_branch_point = m.just_reported_branch_point;
  s->branch_points_found = m.branch_points_found;
  s->march_points = m.points;
  s->refused_steps = m.refused_steps;
  s->has_march = true;
}

ContactMarchState contact_march_state(const RunState& s) {
  return {march_state(s), s.contacts, s.contact_bending_event, s.leg_max_points, s.reported, s.first_leg,
          s.branch_points_before};
}

void set_contact_march_state(RunState* s, const ContactMarchState& m) {
  set_march_state(s, m.march);
  s->contacts = m.contacts;
  s->contact_bending_event = m.contact_bending_event;
  s->leg_max_points = m.leg_max_points;
  s->reported = m.reported;
  s->first_leg = m.first_leg;
  s->branch_points_before = m.branch_points_before;
}

namespace {

// The row's index (its first field) where the row is complete (at least `fields` fields: an
// event's text may hold commas, a row a kill cut short has fewer), else nothing.
std::optional<int> complete_row_index(const std::string& line, size_t fields) {
  if (static_cast<size_t>(std::count(line.begin(), line.end(), ',')) + 1 < fields) return std::nullopt;
  const std::string first = line.substr(0, line.find(','));
  char* end = nullptr;
  const long index = std::strtol(first.c_str(), &end, 10);
  if (first.empty() || *end != '\0' || index < 0 || index > std::numeric_limits<int>::max()) return std::nullopt;
  return static_cast<int>(index);
}

std::runtime_error rows_lost(const std::filesystem::path& path, int last_index, const std::string& what) {
  return std::runtime_error(path.string() + ": " + what + ", where its state file saved the run after row " +
                            std::to_string(last_index) +
                            ": the file was cut or edited, and resuming would lose rows. Restore it, or run again "
                            "without --resume");
}

}  // namespace

// Keeps the header and the rows up to and including `last_index` (rows written after the state
// was last saved are dropped and computed again, so no point is duplicated on resume). Rows are
// in order of their index: reading stops after row last_index, so a line a kill cut short after
// it is dropped whatever its first characters read as. The rows kept must all be there, whole
// and in order (a kill cannot lose them: each is flushed before the state is saved), or the
// resumed file would have a gap.
void truncate_csv(const std::filesystem::path& path, int last_index, const std::string& header, CsvRows rows) {
  std::ifstream in(path);
  std::string kept_header, line, kept;
  std::getline(in, kept_header);
  const size_t fields = static_cast<size_t>(std::count(kept_header.begin(), kept_header.end(), ',')) + 1;
  if (!header.empty()) kept_header = header;
  int previous = -1;
  while (previous < last_index && std::getline(in, line)) {
    if (line.empty()) continue;
    const std::optional<int> index = complete_row_index(line, fields);
    // (Some indices: the rows the state knows of are not known, and a kill may have cut the
    // file's last row, written after the saved one - dropped with the rest, as before.)
    if (!index && rows == CsvRows::SomeIndices) break;
    if (!index) throw rows_lost(path, last_index, "the row after row " + std::to_string(previous) + " is not whole");
    if (*index > last_index) break;
    const bool in_order = rows == CsvRows::EveryIndex ? *index == previous + 1 : *index > previous;
    if (!in_order)
      throw rows_lost(path, last_index,
                      "row " + std::to_string(*index) + " follows row " + std::to_string(previous));
    kept += line + "\n";
    previous = *index;
  }
  if (rows == CsvRows::EveryIndex && previous < last_index)
    throw rows_lost(path, last_index, previous < 0 ? "it holds no rows" : "it ends at row " + std::to_string(previous));
  in.close();
  std::ofstream out(path, std::ios::trunc);
  out << kept_header << "\n" << kept;
}

}  // namespace kirchhoff
