// plan_run (jobs/run_plan.hpp): where a continuation run starts, as `kirchhoff continue` and
// Python's continue_ both plan it - the refusals with their reasons, the restart of a run killed
// before its first save, a resume and a start from a real run's state file.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <fstream>
#include <string>

#include "kirchhoff/jobs/case_continue.hpp"
#include "kirchhoff/jobs/continue_outputs.hpp"
#include "kirchhoff/jobs/run_plan.hpp"

namespace kirchhoff {
namespace {

namespace fs = std::filesystem;

class RunPlanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("kirchhoff_run_plan_" + std::to_string(getpid()));
    fs::create_directories(dir_);
    in_.case_path = std::string(KIRCHHOFF_CASES_DIR) + "/simply_supported.toml";
    request_.parameter = "theta0";
    request_.target = 1.2;
    request_.identity = "the run";
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write_csv(const fs::path& path, int rows) {
    std::ofstream out(path);
    out << "index,branch,theta0\n";
    for (int i = 0; i < rows; ++i) out << i << ",0,1\n";
  }
  // The message of the CaseError plan_run throws ("" when it throws none).
  std::string refusal() {
    try {
      plan_run(in_, &request_);
    } catch (const CaseError& e) {
      return e.what();
    }
    return "";
  }
  // Runs the request's branch to the end, saving its state to `state`.
  void run_saving_state(const fs::path& state) {
    ContinueRequest request = request_;
    StateFileSink sink(state, std::chrono::steady_clock::duration::zero());
    const ContinueRunResult result = continue_case(load_case(in_.case_path), request, {&sink});
    ASSERT_TRUE(result.ok) << result.message;
  }
  fs::path dir_;
  RunPlanInputs in_;
  ContinueRequest request_;
};

TEST_F(RunPlanTest, PlainRunLoadsTheCaseWithTheOverrides) {
  in_.overrides = {{"theta0", 0.9}};
  const RunPlan plan = plan_run(in_, &request_);
  EXPECT_DOUBLE_EQ(plan.c.definition.parameters.get("theta0"), 0.9);
  EXPECT_EQ(request_.set_parameters, in_.overrides);
  EXPECT_FALSE(request_.resume || request_.start || plan.start);
  EXPECT_TRUE(plan.notes.empty());
}

TEST_F(RunPlanTest, RefusalsSayWhy) {
  in_.resume = true;
  EXPECT_NE(refusal().find("needs state=PATH"), std::string::npos);
  in_.state_path = dir_ / "none.state.json";
  EXPECT_NE(refusal().find("no state file"), std::string::npos);
  // Rows beyond the start's and no state: nothing records where the march stood.
  in_.csv_path = dir_ / "run.csv";
  write_csv(in_.csv_path, 3);
  EXPECT_NE(refusal().find("has 3 rows but there is no state file"), std::string::npos) << refusal();
  request_.deflate = true;
  EXPECT_EQ(refusal(), kDeflateRefusal);
  request_.deflate = false;
  in_.resume = false;
  in_.start_from = (dir_ / "other.state.json").string();
  request_.seed.ipopt = true;
  EXPECT_EQ(refusal(), "--start-from does not combine with --seed");
  request_.seed.ipopt = false;
  in_.start_from.clear();
  request_.parameter = "Q";
  EXPECT_NE(refusal().find("--param Q: not a parameter of the case"), std::string::npos) << refusal();
}

// A run killed before it saved its first point has at most the start's row: resuming it starts
// it again, said in a note.
TEST_F(RunPlanTest, ResumeWithoutStateAndAtMostTheStartRowStartsAgain) {
  in_.resume = true;
  in_.state_path = dir_ / "run.csv.state.json";
  in_.csv_path = dir_ / "run.csv";
  write_csv(in_.csv_path, 1);
  const RunPlan plan = plan_run(in_, &request_);
  EXPECT_FALSE(request_.resume.has_value());
  ASSERT_EQ(plan.notes.size(), 1u);
  EXPECT_NE(plan.notes[0].find("starts from the beginning"), std::string::npos) << plan.notes[0];
}

// One identity for the CLI and Python: the case by its canonical path, the values as numbers;
// everything that decides the points changes it.
TEST_F(RunPlanTest, RunIdentityNamesTheRunNotHowItWasTyped) {
  request_.identity.clear();
  in_.overrides = {{"theta0", 1.0}};
  const std::string identity = run_identity(in_, request_);
  RunPlanInputs other = in_;
  other.case_path = std::string(KIRCHHOFF_CASES_DIR) + "/../cases/simply_supported.toml";
  EXPECT_EQ(run_identity(other, request_), identity);
  plan_run(in_, &request_);
  EXPECT_EQ(request_.identity, identity);  // plan_run fills it when the caller did not
  for (auto change : std::vector<std::function<void(RunPlanInputs*, ContinueRequest*)>>{
           [](RunPlanInputs* i, ContinueRequest*) { i->overrides = {{"theta0", 1.1}}; },
           [](RunPlanInputs* i, ContinueRequest*) { i->solver = {{"tolerance", "1e-10"}}; },
           [](RunPlanInputs*, ContinueRequest* r) { r->target = 1.3; },
           [](RunPlanInputs*, ContinueRequest* r) { r->max_step = 0.1; },
           [](RunPlanInputs*, ContinueRequest* r) { r->events.push_back({"theta_end", -1.0, true, ""}); },
           [](RunPlanInputs*, ContinueRequest* r) { r->seed.ipopt = true; }}) {
    RunPlanInputs i = in_;
    ContinueRequest r = request_;
    change(&i, &r);
    EXPECT_NE(run_identity(i, r), identity);
  }
}

// A state file that cannot be read is bad input (CaseError) for both front ends.
TEST_F(RunPlanTest, UnreadableStateFileIsACaseError) {
  in_.resume = true;
  in_.state_path = dir_;  // a folder
  EXPECT_NE(refusal().find("the state file cannot be read"), std::string::npos) << refusal();
}

TEST_F(RunPlanTest, ResumeAndStartFromARunsStateFile) {
  const fs::path state = dir_ / "run.csv.state.json";
  ASSERT_NO_FATAL_FAILURE(run_saving_state(state));
  in_.resume = true;
  in_.state_path = state;
  plan_run(in_, &request_);
  ASSERT_TRUE(request_.resume.has_value());
  // Another run's arguments: resuming would not continue the same run.
  request_.resume.reset();
  request_.identity = "another run";
  EXPECT_NE(refusal().find("other arguments"), std::string::npos) << refusal();
  // Started from it: at its last point, theta0 = 1.2, with the value among the overrides.
  in_.resume = false;
  in_.start_from = state.string();
  request_.target = 2.0;
  const RunPlan plan = plan_run(in_, &request_);
  ASSERT_TRUE(plan.start.has_value());
  ASSERT_TRUE(request_.start.has_value());
  EXPECT_EQ(request_.start_name, state.string());
  EXPECT_NEAR(plan.c.definition.parameters.get("theta0"), 1.2, 1e-12);
  // A case without that run's parameter refuses it, naming the parameter.
  in_.case_path = std::string(KIRCHHOFF_CASES_DIR) + "/euler_column.toml";
  request_.parameter = "P";
  EXPECT_NE(refusal().find("parameter 'theta0'"), std::string::npos) << refusal();
}

}  // namespace
}  // namespace kirchhoff
