// Helpers for tests that run the `kirchhoff` executable: whole runs, runs to be killed, their CSV
// lines, and a scratch folder per test.
#pragma once

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <string>
#include <thread>
#include <vector>

namespace kirchhoff::testing {

namespace fs = std::filesystem;

// A text file's whole contents.
inline std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The non-empty lines of a text file.
inline std::vector<std::string> lines_of(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) out.push_back(line);
  return out;
}

// The comma-separated fields of a CSV line, as text (the project's CSVs quote nothing).
inline std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> out;
  size_t from = 0;
  for (size_t comma; (comma = line.find(',', from)) != std::string::npos; from = comma + 1)
    out.push_back(line.substr(from, comma - from));
  out.push_back(line.substr(from));
  return out;
}

// Each column's position, by the names of a CSV header line.
inline std::map<std::string, int> csv_header(const std::string& line) {
  std::map<std::string, int> out;
  const std::vector<std::string> names = csv_fields(line);
  for (size_t k = 0; k < names.size(); ++k) out[names[k]] = static_cast<int>(k);
  return out;
}

// The k-th comma-separated field of a CSV line, as a number.
inline double csv_field(const std::string& line, int k) {
  size_t pos = 0;
  for (int i = 0; i < k; ++i) pos = line.find(',', pos) + 1;
  return std::stod(line.substr(pos, line.find(',', pos) - pos));
}

// Runs to the end; stderr (and stdout too with `with_stdout`) goes to `log`. Returns the exit status.
inline int run_to_end(const std::vector<std::string>& args, const fs::path& log, bool with_stdout = false) {
  std::string cmd;
  for (const auto& a : args) cmd += "'" + a + "' ";
  const std::string redirect = with_stdout ? " > '" + log.string() + "' 2>&1" : " 2> '" + log.string() + "'";
  return WEXITSTATUS(std::system((cmd + redirect).c_str()));
}

// Starts the run, waits until `ready()` (or a minute and a half), kills it with SIGKILL and
// returns whether it was killed (false: it had already finished).
inline bool run_and_kill(const std::vector<std::string>& args, const fs::path& log,
                         const std::function<bool()>& ready) {
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    FILE* err = std::freopen(log.c_str(), "w", stderr);
    (void)err;
    execv(argv[0], argv.data());
    _exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(90);
  while (!ready() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFSIGNALED(status);
}

// A fresh scratch folder per test, removed afterwards.
class ScratchFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("kirchhoff_cli_" + std::to_string(getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

}  // namespace kirchhoff::testing
