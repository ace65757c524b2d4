// The state file of a long continuation run: a resumable point with the march's whole state
// there, kept beside the branch CSV (branch.csv.state.json) and replaced atomically (by `continue`
// at most once a second, continue_outputs.hpp's StateFileSink; by the plectoneme sweep after
// every such point), so that a killed run resumes from it: the CSV is cut back to the saved
// point's row and the march repeats the rows after it, none lost or duplicated. The JSON format
// is the one earlier versions wrote; their files still load.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "kirchhoff/contact/contact.hpp"
#include "kirchhoff/continuation/continuation.hpp"

namespace kirchhoff {

// A row a run wrote, with what a run started from it (--start-from) needs beside the point: the
// active set its unknowns belong to, the phase condition of its problem and its branch.
struct WrittenPoint {
  int row = -1;
  int branch = 0;
  std::string phase_condition;
  ContinuationPoint point;              // x, parameter, tangent, arclength, index, type
  std::vector<PointContact> contacts;   // contact runs: the active set of the point's leg
};

struct RunState {
  int row = -1;                   // index of the last CSV row written (continuous across branches)
  int saved_row = -1;             // the row of `last`, the point a resume starts from
  int branch = 0;                 // 0: the starting branch, 1: after --switch-at-bp
  std::string phase_condition;    // of the problem the branch belongs to
  std::string parameter_name;     // the parameter continued in (empty in files older than it)
  ContinuationPoint last;
  std::vector<PointContact> contacts;  // the active set of `last` (contact runs)
  std::vector<int> piece_segments;     // multiple shooting with contacts: the problem's segments per piece

  // The rest of the march's state at `last` (MarchState; `continue` saves it so that a resumed
  // run repeats the uninterrupted one; plectonemes' files and those written before 2026-12-02
  // have none: has_march false).
  bool has_march = false;
  std::optional<ContinuationPoint> before;
  double previous_step = 0.0;
  bool just_reported_branch_point = false;
  int branch_points_found = 0;
  int march_points = 1;
  int refused_steps = 0;
  // Contact runs: the leg's state beyond its active set (ContactMarchState).
  double contact_bending_event = 0.0;
  int leg_max_points = 0;
  int reported = 0;
  bool first_leg = true;
  int branch_points_before = 0;
  // The last row written, which may be a point a resume does not start from (an endpoint at
  // --to, a fold, a branch point, an event): where --start-from starts. Absent in older files.
  std::optional<WrittenPoint> written;
  // The run's parameter values beyond the case file's (its --set values and, for a run started
  // from another one, those it started with), in order; a run started from this one keeps them.
  // has_set_parameters is false in files older than the record.
  bool has_set_parameters = false;
  std::vector<std::pair<std::string, double>> set_parameters;
  // The run's arguments, as `continue` words them (a resume with others would not continue the
  // same run); empty in files that did not record them.
  std::string arguments;
};

// The march's state of a RunState and back (`last` is its current point).
MarchState march_state(const RunState& s);
void set_march_state(RunState* s, const MarchState& m);
ContactMarchState contact_march_state(const RunState& s);
void set_contact_march_state(RunState* s, const ContactMarchState& m);

// Points a run can resume from (a special point is re-found by the resumed march, not restarted from).
bool resumable(const ContinuationPoint& p);
void save_state(const std::filesystem::path& path, const RunState& s);
// Makes p, the point of the row last written, the one to resume from, and saves the state.
void save_resume_point(const std::filesystem::path& path, const ContinuationPoint& p, RunState* state);
RunState load_state(const std::filesystem::path& path);
// Where a run started from another run's state file (--start-from) starts, and with which
// parameter values: the case file's, replaced by that run's set values, then by its continued
// parameter at the point, then by the new command line's --set (which may not name that
// parameter: the point is a solution at its own value only).
struct RunStart {
  WrittenPoint at;                 // the point and its active set
  std::string from_parameter;      // the parameter the earlier run continued in
  std::vector<std::pair<std::string, double>> parameters;  // the overrides to load the case with
  // Where each of `parameters` comes from, for the message that lists them ("that run's --set").
  std::vector<std::string> sources;
  std::vector<std::string> notes;  // what an older state file could not say (printed as notes)
};
// Throws std::invalid_argument naming the file and the reason when it cannot be started from.
// start_param names the parameter for files older than parameter_name.
RunStart plan_start_from(const std::filesystem::path& state_path, const std::string& start_param,
                         const std::vector<std::pair<std::string, double>>& command_line);

// Which indices a CSV's rows carry: every one from 0 (a branch's rows), or some, increasing (the
// hard-contact re-solutions of some of a branch's rows, keyed by their row).
enum class CsvRows { EveryIndex, SomeIndices };

// Keeps the header and the rows of a branch CSV up to and including the one whose index (first
// column) is `last_index`; the rows after it, and a row cut short by a kill, are dropped.
// `header`, where not empty, replaces the file's (a renamed column). Throws std::runtime_error
// naming the file where a row up to last_index is missing (EveryIndex), cut short or out of order:
// resuming would lose it.
void truncate_csv(const std::filesystem::path& path, int last_index, const std::string& header = "",
                  CsvRows rows = CsvRows::EveryIndex);

}  // namespace kirchhoff
