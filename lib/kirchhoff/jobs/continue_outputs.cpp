#include "kirchhoff/jobs/continue_outputs.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "kirchhoff/analysis/point_record.hpp"
#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/jobs/detail/csv_number.hpp"

namespace kirchhoff {

namespace fs = std::filesystem;

namespace {

bool same_contacts(const std::vector<PointContact>& a, const std::vector<PointContact>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const PointContact& x, const PointContact& y) {
    return x.obstacle == y.obstacle && x.s == y.s && x.force == y.force && x.extended == y.extended &&
           x.s_end == y.s_end && x.force_end == y.force_end;
  });
}

// The invariants' relative spreads. Earlier versions named them H_spread, m3_spread and
// n_dot_m_spread, which the derived quantity H_spread (absolute, max - min) names too.
constexpr const char* kSpreadColumns = "H_relative_spread,m3_relative_spread,n_dot_m_relative_spread";
constexpr const char* kEarlierSpreadColumns = "H_spread,m3_spread,n_dot_m_spread";

std::string csv_header(const std::string& parameter, const std::vector<std::string>& columns, const char* spreads) {
  std::string header = "index,branch," + parameter + ",arclength";
  for (const auto& d : columns) header += "," + d;
  return header + "," + spreads + ",H_flat,type,multiplicity,event,newton_iterations,stability_index,zero_modes";
}

// A resumed run appends to the CSV of the run it continues: its header must be this run's, or
// the same as an earlier version wrote it (truncate_csv then renames it). Anything else was
// written with other outputs, and rows appended to it would not line up with its columns.
void check_resumed_header(const fs::path& path, const std::string& header, const std::string& earlier) {
  if (!fs::exists(path))
    throw std::runtime_error(path.string() + " is missing, while its state file is there: the rows it held cannot be "
                             "resumed from (restore it, or run again without --resume)");
  std::ifstream in(path);
  std::string found;
  std::getline(in, found);
  if (found == header || found == earlier) return;
  throw std::runtime_error(path.string() + ": its header is not this run's (it has \"" + found + "\", this run writes \"" +
                           header + "\"): written with other outputs; run again without --resume");
}

}  // namespace

void BranchCsvSink::begin(const std::string& parameter, const std::vector<std::string>& columns,
                          int resumed_after_row) {
  columns_ = columns;
  const bool append = resumed_after_row >= 0;
  const std::string header = csv_header(parameter, columns_, kSpreadColumns);
  if (append) {
    check_resumed_header(path_, header, csv_header(parameter, columns_, kEarlierSpreadColumns));
    truncate_csv(path_, resumed_after_row, header);
  }
  out_.open(path_, append ? std::ios::app : std::ios::trunc);
  if (!out_) throw std::runtime_error("cannot write " + path_.string());
  out_ << std::setprecision(detail::kCsvPrecision);  // (every double goes through put_csv_number)
  if (!append) {
    out_ << header << "\n";
    out_.flush();
  }
}

void BranchCsvSink::point(const RunPoint& rp) {
  const ContinuationPoint& p = *rp.point;
  const auto cell = [this](double v) {
    out_ << ',';
    detail::put_csv_number(out_, v);
  };
  out_ << rp.row << ',' << rp.branch;
  cell(p.parameter);
  cell(p.arclength);
  for (const auto& d : columns_) {
    const auto it = p.derived.find(d);
    cell(it != p.derived.end() ? it->second : NAN);
  }
  const auto& inv = invariants_of(p);
  // + 0.0 prints a zero spread as 0, not -0.
  cell(inv.H.relative_spread() + 0.0);
  cell(inv.m3.relative_spread() + 0.0);
  cell(inv.n_dot_m.relative_spread() + 0.0);
  out_ << ',' << (H_is_flat(p) ? 1 : 0) << ',' << to_string(p.type) << ',' << p.multiplicity << ',' << p.event << ','
       << p.newton_iterations << ',';
  // Both empty where the index is not defined (or not computed): never a guessed number.
  if (p.stability_index) out_ << *p.stability_index << ',' << p.zero_modes;
  else out_ << ',';
  out_ << '\n';
  out_.flush();
}

void StateFileSink::save(const RunState& s) {
  save_state(path_, s);
  last_ = std::chrono::steady_clock::now();
  ++saves_;
}

void StateFileSink::state(const RunState& s, bool) {
  if (saves_ == 0 || std::chrono::steady_clock::now() - last_ >= interval_) save(s);
}

void StateFileSink::finish(const RunState* s) {
  if (s && s->has_march) save(*s);  // with the last row written
}

ProfileSink::ProfileSink(const Case& c, std::string parameter, fs::path dir, int samples)
    : case_(c), parameter_(std::move(parameter)), dir_(std::move(dir)), samples_(samples) {
  fs::create_directories(dir_);
}

void ProfileSink::point(const RunPoint& rp) {
  const ShootingProblem* problem = rp.problem;
  if (!problem && rp.contacts) {
    // A contact run's leg: the case with the leg's active set (built again when it changes).
    if (!leg_problem_ || !same_contacts(*rp.contacts, leg_contacts_)) {
      ProblemDefinition d = case_.definition;
      d.contacts = leg_contacts_ = *rp.contacts;
      leg_problem_ = std::make_unique<ShootingProblem>(d);
    }
    problem = leg_problem_.get();
  }
  if (!problem) return;
  const ContinuationPoint& p = *rp.point;
  ShootingProblem copy = *problem;
  copy.set_parameter(parameter_, p.parameter);
  ShootingResult r;
  r.x = p.x;
  r.parameters = copy.parameters_at(p.x);
  const Solution s = make_solution(copy, r, samples_, {});
  std::ostringstream name;
  name << "point_" << std::setw(5) << std::setfill('0') << rp.row << ".csv";
  write_profile_csv((dir_ / name.str()).string(), copy.equations(r.parameters)->model(), s.profile,
                    copy.definition().kind);
}

}  // namespace kirchhoff
