// The state file of a long continuation run: its last resumable point, kept beside the branch
// CSV (branch.csv.state.json) and replaced atomically after every such point, so that a killed
// run resumes from it without losing or duplicating a row. Shared by `continue` and
// `plectonemes`.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "kirchhoff/contact.hpp"
#include "kirchhoff/continuation.hpp"

namespace kirchhoff::cli {

struct RunState {
  int row = -1;                   // index of the last CSV row written (continuous across branches)
  int saved_row = -1;             // the row of `last`, the point a resume starts from
  int branch = 0;                 // 0: the starting branch, 1: after --switch-at-bp
  std::string phase_condition;    // of the problem the branch belongs to
  std::string parameter_name;     // the parameter continued in (empty in files older than it)
  ContinuationPoint last;
  std::vector<PointContact> contacts;  // the active set of `last` (contact runs)
  std::vector<int> piece_segments;     // multiple shooting with contacts: the problem's segments per piece
};

// Points a run can resume from (a special point is re-found by the resumed march, not restarted from).
bool resumable(const ContinuationPoint& p);
void save_state(const std::filesystem::path& path, const RunState& s);
// Makes p, the point of the row last written, the one to resume from, and saves the state.
void save_resume_point(const std::filesystem::path& path, const ContinuationPoint& p, RunState* state);
RunState load_state(const std::filesystem::path& path);
// Keeps the header and the rows whose first column (the row index) is at most `last_index`.
void truncate_csv(const std::filesystem::path& path, int last_index);

}  // namespace kirchhoff::cli
