#include "kirchhoff/sweeps/sweep.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <toml.hpp>

#include "kirchhoff/jobs/detail/toml_nesting.hpp"
#include "kirchhoff/jobs/detail/toml_reader.hpp"

namespace kirchhoff {

const char* to_string(SweepJobKind kind) {
  switch (kind) {
    case SweepJobKind::Solve: return "solve";
    case SweepJobKind::Equilibria: return "equilibria";
    case SweepJobKind::Continue: return "continue";
    case SweepJobKind::Plectonemes: return "plectonemes";
  }
  return "?";
}

namespace {

// An interior value of a linear range, as the decimal the user means: from + (to - from) k / (n - 1)
// rounded to 15 digits of the range's scale, so that {from = -0.5, to = 0.7, count = 3} runs 0.1,
// not 0.09999999999999998 (which index.csv and every output wrote). The change is below 1e-15 of
// the scale, under any tolerance the runs have.
double decimal_near(double value, double scale) {
  if (!(scale > 0) || !std::isfinite(value)) return value;
  const int decimals = std::clamp(15 - static_cast<int>(std::ceil(std::log10(scale))), 0, 300);
  char text[400];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  const double near = std::strtod(text, nullptr);
  return std::abs(near - value) <= 1e-14 * scale ? near : value;
}

using Value = toml::value;
using toml_reading::type_name;

// Ranges hold at most this many points: a larger count is a typo (a 1e6-job sweep is kMaxJobs).
constexpr long kMaxRangeCount = 1000000;
// Default relative costs by kind (a `cost` key replaces them): a solve is about a second, an
// equilibria search a few to tens of solves, a branch hundreds of points, a plectoneme branch
// minutes to hours. Only their order matters: the MPI manager hands out larger jobs first.
double default_cost(SweepJobKind kind) {
  switch (kind) {
    case SweepJobKind::Solve: return 1.0;
    case SweepJobKind::Equilibria: return 10.0;
    case SweepJobKind::Continue: return 100.0;
    case SweepJobKind::Plectonemes: return 10000.0;
  }
  return 1.0;
}

// A value as text that reads back to the same double (17 significant digits, where messages
// show 15): the fingerprint tells values apart by it, and a [solver] number reaches the case
// loader as this text.
std::string exact_text(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

// Entries of a table in the order of the file (toml11 keeps a table's keys unordered): the
// grid's first key varies slowest, as in a nested loop written in that order.
std::vector<std::pair<std::string, const Value*>> in_file_order(const toml::table& table) {
  std::vector<std::pair<std::string, const Value*>> entries;
  for (const auto& entry : table) entries.emplace_back(entry.first, &entry.second);
  std::sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
    const auto &la = a.second->location(), &lb = b.second->location();
    return std::pair(la.line(), la.column()) < std::pair(lb.line(), lb.column());
  });
  return entries;
}

// Reads the sweep file's keys, turning every problem into a SweepError naming the file, the line,
// the key and the reason, in the case files' words (toml_reader.hpp); adds what only sweep files
// hold: a parameter's values (a number, a list or a range), overrides and [solver] keys.
class Reader : public toml_reading::KeyReader<SweepError> {
 public:
  using KeyReader::KeyReader;

  // A parameter's values: a number, an array of numbers, or a range
  // { from, to, count [, log = true] } (count points, both ends included; log: evenly spaced in
  // log10, from and to > 0).
  std::vector<double> values(const Value& v, const std::string& key) const {
    if (v.is_array()) {
      const auto& a = v.as_array();
      if (a.empty()) fail(v, key, "an empty array: no values to sweep");
      if (a.size() > sweep_limits::kMaxJobs)
        fail(v, key, "more than " + std::to_string(sweep_limits::kMaxJobs) + " values");
      std::vector<double> out;
      for (std::size_t i = 0; i < a.size(); ++i) out.push_back(number(a[i], key + "[" + std::to_string(i) + "]"));
      return out;
    }
    if (v.is_table()) {
      allow_keys(v, key, {"from", "to", "count", "log"});
      for (const char* required : {"from", "to", "count"})
        if (!find(v, required))
          fail(v, key, std::string("a range needs from, to and count (") + required + " is missing)");
      const double from = number(*find(v, "from"), key + ".from");
      const double to = number(*find(v, "to"), key + ".to");
      const long count = integer(*find(v, "count"), key + ".count", 1, kMaxRangeCount);
      const bool log = find(v, "log") && boolean(*find(v, "log"), key + ".log");
      if (log && !(from > 0 && to > 0)) fail(v, key, "a log range needs from > 0 and to > 0");
      if (count == 1 && from != to) fail(v, key, "count = 1 needs from = to");
      std::vector<double> out;
      for (long k = 0; k < count; ++k) {
        // The ends exactly as written; interior points from the ends, not by accumulated steps.
        if (k == 0) out.push_back(from);
        else if (k == count - 1) out.push_back(to);
        else if (log)
          out.push_back(std::pow(10.0, std::log10(from) + (std::log10(to) - std::log10(from)) * static_cast<double>(k) /
                                                              static_cast<double>(count - 1)));
        else
          out.push_back(decimal_near(from + (to - from) * static_cast<double>(k) / static_cast<double>(count - 1),
                                     std::max(std::abs(from), std::abs(to))));
      }
      return out;
    }
    return {number(v, key)};
  }

  // NAME = number overrides (a table).
  ParameterOverrides overrides(const Value& v, const std::string& key) const {
    if (!v.is_table()) fail(v, key, "must be a table of NAME = number, got " + type_name(v));
    ParameterOverrides out;
    for (const auto& [name, value] : in_file_order(v.as_table())) out.emplace_back(name, number(*value, key + "." + name));
    return out;
  }

  // [solver] keys as the case loader's --solver texts.
  SolverOverrides solver(const Value& v, const std::string& key) const {
    if (!v.is_table()) fail(v, key, "must be a table of [solver] keys, got " + type_name(v));
    SolverOverrides out;
    for (const auto& [name, value] : in_file_order(v.as_table())) {
      if (value->is_string()) out.emplace_back(name, value->as_string().str);
      else if (value->is_boolean()) out.emplace_back(name, value->as_boolean() ? "true" : "false");
      else out.emplace_back(name, exact_text(number(*value, key + "." + name)));
    }
    return out;
  }
};

SweepJobKind parse_kind(const Reader& r, const Value& v, const std::string& key) {
  const std::string s = r.string(v, key);
  if (s == "solve") return SweepJobKind::Solve;
  if (s == "equilibria") return SweepJobKind::Equilibria;
  if (s == "continue") return SweepJobKind::Continue;
  if (s == "plectonemes") return SweepJobKind::Plectonemes;
  r.fail(v, key, "unknown job kind '" + s + "' (expected one of: solve, equilibria, continue, plectonemes)");
}

bool valid_name(const std::string& s) {
  if (s.empty() || s.size() > 64) return false;
  return std::all_of(s.begin(), s.end(), [](char ch) {
    return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_' || ch == '-';
  });
}

std::string padded(std::size_t k, std::size_t count) {
  std::string s = std::to_string(k);
  const std::size_t width = std::max<std::size_t>(3, std::to_string(count).size());
  return std::string(width > s.size() ? width - s.size() : 0, '0') + s;
}

// The points of one [[jobs]] table: a grid's Cartesian product (first key slowest), or the list.
// `where` gets each swept name's value in the file (for messages).
std::vector<ParameterOverrides> points(const Reader& r, const Value& group, const std::string& key,
                                       std::map<std::string, std::pair<const Value*, std::string>>* where) {
  const Value* grid = Reader::find(group, "grid");
  const Value* list = Reader::find(group, "list");
  if (grid && list) r.fail(*list, key + ".list", "give either grid or list, not both");
  std::vector<ParameterOverrides> out;
  if (grid) {
    if (!grid->is_table()) r.fail(*grid, key + ".grid", "must be a table NAME = values, got " + type_name(*grid));
    out.push_back({});
    for (const auto& [name, value] : in_file_order(grid->as_table())) {
      const std::vector<double> values = r.values(*value, key + ".grid." + name);
      where->emplace(name, std::pair(value, key + ".grid." + name));
      if (out.size() * values.size() > sweep_limits::kMaxJobs)
        r.fail(*value, key + ".grid." + name, "the grid has more than " + std::to_string(sweep_limits::kMaxJobs) + " points");
      std::vector<ParameterOverrides> next;
      for (const auto& p : out)
        for (double x : values) {
          next.push_back(p);
          next.back().emplace_back(name, x);
        }
      out = std::move(next);
    }
    return out;
  }
  if (list) {
    if (!list->is_array() || list->as_array().empty())
      r.fail(*list, key + ".list", "must be a non-empty array of tables { NAME = number, ... }");
    const auto& a = list->as_array();
    if (a.size() > sweep_limits::kMaxJobs) r.fail(*list, key + ".list", "too many entries");
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string entry = key + ".list[" + std::to_string(i) + "]";
      out.push_back(r.overrides(a[i], entry));
      if (a[i].is_table())
        for (const auto& [name, value] : a[i].as_table()) where->emplace(name, std::pair(&value, entry + "." + name));
    }
    return out;
  }
  return {ParameterOverrides{}};  // one job at the case's values (and the overrides)
}

std::string resolve(const std::string& sweep_path, const std::string& case_path) {
  const std::filesystem::path p(case_path);
  if (p.is_absolute()) return case_path;
  const std::filesystem::path folder = std::filesystem::path(sweep_path).parent_path();
  return (folder / p).lexically_normal().string();
}

}  // namespace

std::string SweepJob::fingerprint() const {
  std::ostringstream os;
  os << to_string(kind) << " case=" << case_name;
  for (const auto& [name, value] : values) os << " " << name << "=" << exact_text(value);
  os << " set:";
  for (const auto& [name, value] : set) os << " " << name << "=" << exact_text(value);
  os << " solver:";
  for (const auto& [name, value] : solver) os << " " << name << "=" << value;
  os << " direct=" << direct << " max_seconds=" << exact_text(max_seconds) << " max_equilibria=" << max_equilibria
     << " profiles=" << profiles;
  if (kind == SweepJobKind::Continue)
    os << " param=" << param << " to=" << exact_text(to) << " max_points=" << max_points
       << " step=" << exact_text(step) << " min_step=" << exact_text(min_step) << " max_step=" << exact_text(max_step)
       << " branch_points=" << branch_points << " stability=" << stability;
  if (kind == SweepJobKind::Plectonemes)
    os << " from_ply=" << exact_text(from_ply) << " from_ply_turns=" << exact_text(from_ply_turns)
       << " hard_from=" << exact_text(hard_from);
  return os.str();
}

ParameterOverrides SweepJob::overrides() const {
  ParameterOverrides out;
  for (const auto& entry : set) {
    const std::string& name = entry.first;
    if (std::none_of(values.begin(), values.end(), [&name](const auto& v) { return v.first == name; }))
      out.push_back(entry);
  }
  for (const auto& entry : values) out.push_back(entry);
  return out;
}

SweepSpec load_sweep(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SweepError(path + ": cannot open the file (" + std::strerror(errno) + ")");
  std::string text(sweep_limits::kMaxFileBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) throw SweepError(path + ": cannot read the file (" + std::strerror(errno) + ")");
  text.resize(static_cast<std::size_t>(in.gcount()));
  return load_sweep_text(text, path);
}

namespace {

// The file's text checked for size, nesting and encoding, then parsed.
Value parse_sweep_text(const std::string& text, const std::string& path) {
  if (text.size() > sweep_limits::kMaxFileBytes) throw SweepError(path + ": larger than 1 MiB: not a sweep file");
  if (const int line = toml_line_beyond_nesting(text, case_limits::kMaxNesting))
    throw SweepError(path + ":" + std::to_string(line) + ": arrays and tables nest too deeply");
  if (const std::size_t at = toml_invalid_utf8_at(text); at < text.size())
    throw SweepError(path + ": not valid UTF-8 (byte " + std::to_string(at) + ")");
  try {
    std::istringstream stream(text);
    return toml::parse(stream, path);
  } catch (const std::exception& e) {
    throw SweepError(path + ": TOML syntax error: " + e.what());
  }
}

// The file's top-level keys: what every [[jobs]] table starts from.
struct SweepTop {
  std::string case_text;
  const Value* case_value = nullptr;
  ParameterOverrides set;
  SolverOverrides solver;
  const Value* set_value = nullptr;     // where the file gives them, if it does
  const Value* solver_value = nullptr;
  const Value* jobs = nullptr;  // a non-empty array
};

SweepTop read_top(const Reader& r, const Value& root, SweepSpec* spec) {
  r.allow_keys(root, "", {"title", "case", "set", "solver", "jobs"});
  SweepTop top;
  if (const Value* v = Reader::find(root, "title")) spec->title = r.string(*v, "title");
  top.case_value = Reader::find(root, "case");
  if (top.case_value) top.case_text = r.string(*top.case_value, "case");
  top.set_value = Reader::find(root, "set");
  top.solver_value = Reader::find(root, "solver");
  if (top.set_value) top.set = r.overrides(*top.set_value, "set");
  if (top.solver_value) top.solver = r.solver(*top.solver_value, "solver");
  top.jobs = Reader::find(root, "jobs");
  if (!top.jobs) r.fail("jobs", "no [[jobs]] tables: nothing to run");
  if (!top.jobs->is_array() || top.jobs->as_array().empty())
    r.fail(*top.jobs, "jobs", "must be [[jobs]] tables (an array of tables), got " + type_name(*top.jobs));
  return top;
}

// One [[jobs]] table as it is read: its key in messages, its values and where its case came from.
struct Group {
  const Value& table;
  std::string key;         // "jobs[<g>]"
  std::string name;        // prefix of the job ids
  SweepJob prototype;      // every job of the group, before its point's values
  const Value* case_value = nullptr;  // the group's `case`, else the top-level one
  std::string case_key;               // the key that names it
};

// kind and name (unique across the file: it prefixes the job ids and names folders).
void read_kind_and_name(const Reader& r, Group* g, std::set<std::string>* names) {
  const Value* kind = Reader::find(g->table, "kind");
  if (!kind) r.fail(g->table, g->key + ".kind", "missing (solve, equilibria, continue or plectonemes)");
  g->prototype.kind = parse_kind(r, *kind, g->key + ".kind");
  g->name = to_string(g->prototype.kind);
  const Value* name = Reader::find(g->table, "name");
  if (name) {
    g->name = r.string(*name, g->key + ".name");
    if (!valid_name(g->name))
      r.fail(*name, g->key + ".name", "'" + g->name + "' is not 1-64 letters, digits, '_' or '-' (it names folders)");
  }
  if (!names->insert(g->name).second)
    r.fail(name ? *name : g->table, g->key + ".name",
           "'" + g->name + "' names another [[jobs]] table too: give each its own name (it prefixes the job ids)");
}

// The case (the group's, else the file's, resolved against the file's folder), the overrides
// (the file's, replaced or extended by the group's) and the [solver] keys (the file's, then the
// group's).
void read_case_and_overrides(const Reader& r, const SweepTop& top, Group* g) {
  std::string case_text = top.case_text;
  g->case_value = Reader::find(g->table, "case");
  if (g->case_value) case_text = r.string(*g->case_value, g->key + ".case");
  g->case_key = g->case_value ? g->key + ".case" : "case";
  if (!g->case_value) g->case_value = top.case_value;
  if (case_text.empty()) r.fail(g->table, g->key + ".case", "no case: give `case` at the top or in the [[jobs]] table");
  SweepJob& job = g->prototype;
  job.case_path = resolve(r.path(), case_text);
  job.case_name = case_text;
  job.set = top.set;
  if (const Value* v = Reader::find(g->table, "set"))
    for (auto& [n, x] : r.overrides(*v, g->key + ".set")) {
      const std::string nn = n;
      auto it = std::find_if(job.set.begin(), job.set.end(), [&nn](const auto& e) { return e.first == nn; });
      if (it != job.set.end()) it->second = x;
      else job.set.emplace_back(n, x);
    }
  job.solver = top.solver;
  if (const Value* v = Reader::find(g->table, "solver"))
    for (auto& entry : r.solver(*v, g->key + ".solver")) job.solver.push_back(entry);
}

// cost, direct, max_seconds, max_equilibria, profiles.
void read_job_options(const Reader& r, Group* g) {
  SweepJob& job = g->prototype;
  const std::string& key = g->key;
  job.cost = default_cost(job.kind);
  if (const Value* v = Reader::find(g->table, "cost")) {
    job.cost = r.number(*v, key + ".cost");
    if (!(job.cost > 0)) r.fail(*v, key + ".cost", "must be > 0");
  }
  if (const Value* v = Reader::find(g->table, "direct")) {
    if (job.kind != SweepJobKind::Solve) r.fail(*v, key + ".direct", "only solve jobs take it");
    job.direct = r.boolean(*v, key + ".direct");
  }
  if (const Value* v = Reader::find(g->table, "max_seconds")) {
    job.max_seconds = r.number(*v, key + ".max_seconds");
    if (job.max_seconds < 0) r.fail(*v, key + ".max_seconds", "must be >= 0 (0: no limit)");
  }
  if (const Value* v = Reader::find(g->table, "max_equilibria")) {
    if (job.kind != SweepJobKind::Equilibria) r.fail(*v, key + ".max_equilibria", "only equilibria jobs take it");
    job.max_equilibria = r.integer(*v, key + ".max_equilibria", 1, 1000);
  }
  if (const Value* v = Reader::find(g->table, "profiles")) job.profiles = r.boolean(*v, key + ".profiles");
}

// continue's keys are refused on other kinds; plectonemes' keys (from_ply, from_ply_turns,
// hard_from) read, and refused on other kinds, and a plectonemes job's set and solver refused.
void read_kind_keys(const Reader& r, Group* g) {
  SweepJob& job = g->prototype;
  const std::string& key = g->key;
  for (const char* k : {"param", "to", "max_points", "step", "min_step", "max_step", "branch_points", "stability"})
    if (const Value* v = Reader::find(g->table, k); v && job.kind != SweepJobKind::Continue)
      r.fail(*v, key + "." + k, "only continue jobs take it");
  for (auto [k, field] : {std::pair<const char*, double*>{"from_ply", &job.from_ply},
                          {"from_ply_turns", &job.from_ply_turns}, {"hard_from", &job.hard_from}})
    if (const Value* v = Reader::find(g->table, k)) {
      if (job.kind != SweepJobKind::Plectonemes) r.fail(*v, key + "." + k, "only plectonemes jobs take it");
      *field = r.number(*v, key + "." + k);
      if (!(*field >= 0)) r.fail(*v, key + "." + k, "must be >= 0");
    }
  if (job.kind != SweepJobKind::Plectonemes) return;
  if (const Value* v = Reader::find(g->table, "set"))
    r.fail(*v, key + ".set", "plectonemes jobs run their case file as it is (slenderness and turns from the grid or list)");
  if (const Value* v = Reader::find(g->table, "solver")) r.fail(*v, key + ".solver", "plectonemes jobs take the case's [solver]");
}

// A continue job's branch: param (required), to, max_points, the steps, branch_points, stability.
void read_continue_keys(const Reader& r, Group* g) {
  SweepJob& job = g->prototype;
  const std::string& key = g->key;
  const Value* param = Reader::find(g->table, "param");
  if (!param) r.fail(g->table, key + ".param", "missing: the parameter a continue job follows its branch in");
  job.param = r.string(*param, key + ".param");
  if (const Value* v = Reader::find(g->table, "to")) job.to = r.number(*v, key + ".to");
  if (const Value* v = Reader::find(g->table, "max_points"))
    job.max_points = r.integer(*v, key + ".max_points", 1, 1000000);
  for (auto [k, field] :
       {std::pair<const char*, double*>{"step", &job.step}, {"min_step", &job.min_step}, {"max_step", &job.max_step}})
    if (const Value* v = Reader::find(g->table, k)) {
      *field = r.number(*v, key + "." + k);
      if (!(*field > 0)) r.fail(*v, key + "." + k, "must be > 0");
    }
  // (Checked here with the file, as `continue` checks it: a job refused when it ran was a
  // bad_input row of a sweep that had said the file was sound, a probe's.)
  if (!(job.min_step <= job.max_step)) {
    const Value* at = Reader::find(g->table, "min_step") ? Reader::find(g->table, "min_step") : Reader::find(g->table, "max_step");
    std::ostringstream why;
    why << "min_step (" << job.min_step << ") must not exceed max_step (" << job.max_step << ")";
    r.fail(at ? *at : g->table, key + (Reader::find(g->table, "min_step") ? ".min_step" : ".max_step"), why.str());
  }
  if (const Value* v = Reader::find(g->table, "branch_points")) job.branch_points = r.boolean(*v, key + ".branch_points");
  if (const Value* v = Reader::find(g->table, "stability")) job.stability = r.boolean(*v, key + ".stability");
}

using SweptKeys = std::map<std::string, std::pair<const Value*, std::string>>;  // name -> (value, key)

// Why the group's case did not load with its overrides, reported at the key that refuses it,
// found by loading the case with less: the case alone, then with the overrides, then with the
// [solver] keys.
[[noreturn]] void fail_where_refused(const Reader& r, const SweepTop& top, const Group& g) {
  const auto fail_at = [&](const Value* group_value, const Value* top_value, const std::string& key,
                           const std::string& why) {
    if (group_value) r.fail(*group_value, g.key + "." + key, why);
    if (top_value) r.fail(*top_value, key, why);
    r.fail(g.case_value ? *g.case_value : g.table, g.case_key, why);
  };
  const Value* group_set = Reader::find(g.table, "set");
  Case plain;
  try {
    plain = load_case(g.prototype.case_path);
  } catch (const CaseError& e) {
    r.fail(g.case_value ? *g.case_value : g.table, g.case_key, e.what());
  }
  for (const auto& [name, value] : g.prototype.set)
    if (!plain.file_parameters.contains(name)) {
      std::string have;
      for (const auto& n : plain.file_parameters.names()) have += (have.empty() ? "" : ", ") + n;
      const Value* in_group = group_set ? Reader::find(*group_set, name) : nullptr;
      fail_at(in_group, in_group || !top.set_value ? nullptr : Reader::find(*top.set_value, name), "set." + name,
              "no parameter '" + name + "' in " + g.prototype.case_path + " (have: " + have + ")");
    }
  try {
    load_case(g.prototype.case_path, g.prototype.set);
  } catch (const CaseError& e) {
    fail_at(group_set, top.set_value, "set", e.what());
  }
  try {
    load_case(g.prototype.case_path, g.prototype.set, "", g.prototype.solver);
  } catch (const CaseError& e) {
    fail_at(Reader::find(g.table, "solver"), top.solver_value, "solver", e.what());
  }
  throw std::logic_error("sweep: a case refused with its overrides loaded with them");
}

// The group's case loaded with its overrides (once, where the file is sound); what refuses it is
// reported at the key that gives it (fail_where_refused: a probe's `set = { Q = 1 }` on line 2 was
// reported at line 1, key 'case'). Adds the case's derived names to the columns.
Case load_group_case(const Reader& r, const SweepTop& top, const Group& g, SweepSpec* spec) {
  Case c;
  try {
    c = load_case(g.prototype.case_path, g.prototype.set, "", g.prototype.solver);
  } catch (const CaseError&) {
    fail_where_refused(r, top, g);
  }
  for (const auto& d : c.derived)
    if (std::find(spec->derived_columns.begin(), spec->derived_columns.end(), d) == spec->derived_columns.end())
      spec->derived_columns.push_back(d);
  return c;
}

// The continued and swept parameters exist in the case and are not computed ones.
void check_parameters(const Reader& r, const Group& g, const Case& c, const SweptKeys& where) {
  const std::string& case_path = g.prototype.case_path;
  if (const Value* param = Reader::find(g.table, "param")) {
    if (!c.file_parameters.contains(g.prototype.param))
      r.fail(*param, g.key + ".param", "no parameter '" + g.prototype.param + "' in " + case_path);
    if (const std::string refusal =
            dependent_parameter_refusal(c.definition.dependent_parameters, g.prototype.param, "continue in");
        !refusal.empty())
      r.fail(*param, g.key + ".param", refusal);
  }
  for (const auto& [pname, at] : where) {
    if (!c.file_parameters.contains(pname)) {
      std::string have;
      for (const auto& n : c.file_parameters.names()) have += (have.empty() ? "" : ", ") + n;
      r.fail(*at.first, at.second, "no parameter '" + pname + "' in " + case_path + " (have: " + have + ")");
    }
    if (const std::string refusal = dependent_parameter_refusal(c.definition.dependent_parameters, pname, "sweep");
        !refusal.empty())
      r.fail(*at.first, at.second, refusal);
  }
}

// The case at the group's first point (refused values are reported before any job runs), and a
// plectonemes job's slenderness and turns at every point.
void check_points(const Reader& r, const Group& g, const std::vector<ParameterOverrides>& group_points) {
  try {
    SweepJob first = g.prototype;
    first.values = group_points.front();
    load_case(g.prototype.case_path, first.overrides(), "", g.prototype.solver);
  } catch (const CaseError& e) {
    r.fail(g.table, g.key, std::string("at its first point: ") + e.what());
  }
  if (g.prototype.kind != SweepJobKind::Plectonemes) return;
  for (const char* needed : {"slenderness", "turns"})
    for (const auto& point : group_points)
      if (std::none_of(point.begin(), point.end(), [needed](const auto& e) { return e.first == needed; }))
        r.fail(g.table, g.key, std::string("a plectonemes job needs '") + needed +
                                   "' in its grid or list (the branch's L/2R and its largest turns)");
}

// One job per point, ids "<name>-<k>" (or the name alone for a single point), in order.
void expand_jobs(const Reader& r, const Group& g, const std::vector<ParameterOverrides>& group_points,
                 SweepSpec* spec) {
  if (spec->jobs.size() + group_points.size() > sweep_limits::kMaxJobs)
    r.fail(g.table, g.key, "the sweep has more than " + std::to_string(sweep_limits::kMaxJobs) + " jobs");
  for (std::size_t k = 0; k < group_points.size(); ++k) {
    SweepJob job = g.prototype;
    job.id = group_points.size() == 1 ? g.name : g.name + "-" + padded(k + 1, group_points.size());
    // Names are unique, but a name can be another table's id ("x-001" beside a table "x" of two
    // points): one job's folder and row would stand for both, and --resume refuse the file.
    for (const SweepJob& other : spec->jobs)
      if (other.id == job.id) {
        const Value* name = Reader::find(g.table, "name");
        r.fail(name ? *name : g.table, g.key + ".name",
               "its job id '" + job.id + "' is another table's job id too: give a name that no other table's "
               "ids (NAME-001, NAME-002, ...) repeat");
      }
    job.order = static_cast<int>(spec->jobs.size());
    job.values = group_points[k];
    for (const auto& entry : job.values)
      if (std::find(spec->parameter_columns.begin(), spec->parameter_columns.end(), entry.first) ==
          spec->parameter_columns.end())
        spec->parameter_columns.push_back(entry.first);
    spec->jobs.push_back(std::move(job));
  }
}

// The g-th [[jobs]] table (from 0), read, checked against its case and expanded into jobs.
void read_group(const Reader& r, const SweepTop& top, std::size_t index, std::set<std::string>* names,
                SweepSpec* spec) {
  Group g{top.jobs->as_array()[index], "jobs[" + std::to_string(index + 1) + "]", "", SweepJob{}, nullptr, ""};
  r.allow_keys(g.table, g.key, {"name", "kind", "case", "set", "solver", "grid", "list", "cost", "direct", "max_seconds",
                                "max_equilibria", "profiles", "param", "to", "max_points", "step", "min_step",
                                "max_step", "branch_points", "stability", "from_ply", "from_ply_turns", "hard_from"});
  read_kind_and_name(r, &g, names);
  read_case_and_overrides(r, top, &g);
  read_job_options(r, &g);
  read_kind_keys(r, &g);
  if (g.prototype.kind == SweepJobKind::Continue) read_continue_keys(r, &g);
  SweptKeys where;
  const std::vector<ParameterOverrides> group_points = points(r, g.table, g.key, &where);
  // The case, loaded once with the group's overrides, then with its first point: a case that
  // does not load, unknown or computed parameters and refused values are reported before any
  // job runs, at the key that names them.
  const Case c = load_group_case(r, top, g, spec);
  check_parameters(r, g, c, where);
  check_points(r, g, group_points);
  expand_jobs(r, g, group_points, spec);
}

}  // namespace

SweepSpec load_sweep_text(const std::string& text, const std::string& path) {
  const Value root = parse_sweep_text(text, path);
  const Reader r(path);
  SweepSpec spec;
  spec.path = path;
  const SweepTop top = read_top(r, root, &spec);
  std::set<std::string> names;
  for (std::size_t g = 0; g < top.jobs->as_array().size(); ++g) read_group(r, top, g, &names, &spec);
  return spec;
}

}  // namespace kirchhoff
