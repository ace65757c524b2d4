// The outputs of a continuation run (case_continue.hpp) that both front ends can use: the branch
// CSV, the state file a killed run resumes from, and each point's profile.
#pragma once

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "kirchhoff/jobs/case_continue.hpp"

namespace kirchhoff {

// The branch CSV: one row per point, `index,branch,<parameter>,arclength,<columns...>,
// H_relative_spread,m3_relative_spread,n_dot_m_relative_spread,H_flat,type,multiplicity,event,
// newton_iterations,stability_index,zero_modes`. A resumed run keeps the header (refusing a CSV
// whose header is another run's) and the rows up to the one its state was saved at, and appends.
// Each row is flushed as it is written (a state saved after it never points past the file).
class BranchCsvSink : public ContinueSink {
 public:
  explicit BranchCsvSink(std::filesystem::path path) : path_(std::move(path)) {}
  void begin(const std::string& parameter, const std::vector<std::string>& columns, int resumed_after_row) override;
  void point(const RunPoint& p) override;

 private:
  std::filesystem::path path_;
  std::ofstream out_;
  std::vector<std::string> columns_;
};

// The state file beside the CSV (CSV.state.json, run_state.hpp), replaced atomically. Saved at
// the run's first state, then at most once per `interval` (zero: at every state the run gives,
// i.e. after every point), and at the end. A run killed between two saves resumes from the
// last one: its CSV is cut back to that save's row and the rows after it are computed again,
// the same rows (the march repeats the uninterrupted one), so none is lost or duplicated.
class StateFileSink : public ContinueSink {
 public:
  StateFileSink(std::filesystem::path path, std::chrono::steady_clock::duration interval)
      : path_(std::move(path)), interval_(interval) {}
  void state(const RunState& s, bool resumable) override;
  void finish(const RunState* s) override;
  int saves() const { return saves_; }

 private:
  void save(const RunState& s);
  std::filesystem::path path_;
  std::chrono::steady_clock::duration interval_;
  std::chrono::steady_clock::time_point last_ = {};
  int saves_ = 0;
};

// DIR/point_NNNNN.csv: each point's solution along the rod, `samples` points, in the problem it
// belongs to (a contact run's leg: the case with the leg's active set). Points whose problem is
// not known (deflated runs) have none.
class ProfileSink : public ContinueSink {
 public:
  ProfileSink(const Case& c, std::string parameter, std::filesystem::path dir, int samples);
  void point(const RunPoint& p) override;

 private:
  const Case& case_;
  std::string parameter_;
  std::filesystem::path dir_;
  int samples_;
  std::vector<PointContact> leg_contacts_;
  std::unique_ptr<ShootingProblem> leg_problem_;
};

}  // namespace kirchhoff
