// truncate_csv, which --resume cuts a CSV back with: the rows up to the saved one are kept, those
// after it and a row a kill cut short are dropped, and a file that lost rows the state counts on
// is refused rather than resumed with a gap.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli_run_support.hpp"
#include "kirchhoff/jobs/detail/csv_number.hpp"
#include "kirchhoff/jobs/run_state.hpp"

namespace {

namespace fs = std::filesystem;
using kirchhoff::CsvRows;
using kirchhoff::truncate_csv;
using kirchhoff::testing::read_text;

class TruncateCsv : public kirchhoff::testing::ScratchFolderTest {
 protected:
  fs::path write(const std::string& text) {
    const fs::path path = dir_ / "rows.csv";
    std::ofstream(path, std::ios::trunc) << text;
    return path;
  }
};

TEST_F(TruncateCsv, KeepsTheRowsUpToTheSavedOneAndDropsACutLastRow) {
  const fs::path path = write("index,a,b\n0,1,2\n1,3,4\n2,5,6\n3,7");
  truncate_csv(path, 1);
  EXPECT_EQ(read_text(path), "index,a,b\n0,1,2\n1,3,4\n");
}

TEST_F(TruncateCsv, RefusesAFileThatLostRowsBeforeTheSavedOne) {
  const std::string whole = "index,a,b\n0,1,2\n1,3,4\n2,5,6\n";
  for (const std::string& lost : {std::string("index,a,b\n0,1,2\n"), std::string("index,a,b\n0,1,2\n2,5,6\n"),
                                  std::string("index,a,b\n0,1,2\n1,3\n2,5,6\n"), std::string("index,a,b\n")}) {
    SCOPED_TRACE(lost);
    const fs::path path = write(lost);
    EXPECT_THROW(truncate_csv(path, 2), std::runtime_error);
    EXPECT_EQ(read_text(path), lost);  // left as it was
  }
  const fs::path path = write(whole);
  EXPECT_NO_THROW(truncate_csv(path, 2));
  EXPECT_EQ(read_text(path), whole);
}

// The hard-contact re-solutions carry some of the branch's indices: gaps are theirs, and a cut
// last row after the saved one is dropped.
TEST_F(TruncateCsv, SomeIndicesMayHaveGapsButNotGoBack) {
  const fs::path path = write("index,a\n0,1\n4,2\n9,3\n12,");
  truncate_csv(path, 10, "", CsvRows::SomeIndices);
  EXPECT_EQ(read_text(path), "index,a\n0,1\n4,2\n9,3\n");
  const fs::path back = write("index,a\n0,1\n4,2\n3,3\n");
  EXPECT_THROW(truncate_csv(back, 10, "", CsvRows::SomeIndices), std::runtime_error);
}

// The branch CSV's numbers are written by to_chars (detail/csv_number.hpp): the very text the
// stream wrote them as before (setprecision(15), printf's %.15g), so that resumed runs append
// rows identical to an uninterrupted run's and earlier CSVs compare equal.
TEST(CsvNumber, WritesWhatTheStreamWrote) {
  std::vector<double> values = {0.0, -0.0, 1.0, -1.0, 0.1, 1.0 / 3.0, 9.869604401089358, 1e-300, 5e-324,
                                123456789012345678.0, 1e15, 1e16, 1e-5, 1e-4, 2.5e-7, 65.25036310,
                                std::numeric_limits<double>::max(), std::numeric_limits<double>::quiet_NaN(),
                                -std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                                -std::numeric_limits<double>::infinity()};
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-40, 40);
  for (int i = 0; i < 2000; ++i) values.push_back(std::ldexp(mantissa(random), exponent(random)));
  for (double v : values) {
    std::ostringstream by_stream, by_chars;
    by_stream << std::setprecision(15) << v;
    kirchhoff::detail::put_csv_number(by_chars, v);
    EXPECT_EQ(by_chars.str(), by_stream.str()) << std::hexfloat << v;
  }
}

}  // namespace
