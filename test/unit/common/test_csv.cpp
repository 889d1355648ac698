#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "gesture_formation/common/csv.hpp"

using namespace gesture_formation::common;

namespace {
std::string writeTemp(const std::string& name, const std::string& content) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << content;
  return path;
}
}  // namespace

TEST(CsvTest, ParseDouble) {
  EXPECT_DOUBLE_EQ(*parseDouble("1.5"), 1.5);
  EXPECT_DOUBLE_EQ(*parseDouble("-2e3"), -2000.0);
  EXPECT_TRUE(std::isnan(*parseDouble("nan")));
  EXPECT_TRUE(std::isinf(*parseDouble("inf")));
  EXPECT_FALSE(parseDouble(""));
  EXPECT_FALSE(parseDouble("1.5x"));
  EXPECT_FALSE(parseDouble("abc"));
}

TEST(CsvTest, FormatDoubleRoundTripsTenDigits) {
  EXPECT_EQ(formatDouble(std::nan("")), "nan");
  EXPECT_EQ(formatDouble(-INFINITY), "-inf");
  const double v = 123.456789012345;
  EXPECT_NEAR(*parseDouble(formatDouble(v)), v, 1e-7);
}

TEST(CsvTest, SplitTrimsSpacesAndCarriageReturn) {
  const auto f = splitCsvLine(" a, b ,,c\r");
  ASSERT_EQ(f.size(), 4u);
  EXPECT_EQ(f[0], "a");
  EXPECT_EQ(f[1], "b");
  EXPECT_EQ(f[2], "");
  EXPECT_EQ(f[3], "c");
}

TEST(CsvTest, ReaderNamesFileLineAndField) {
  const auto path = writeTemp("csv_a.csv", "t,x\n0,1\n\n1,abc\n");
  CsvReader r(path);
  ASSERT_TRUE(r.requireColumns({"t", "x"}));
  ASSERT_TRUE(r.next());
  EXPECT_DOUBLE_EQ(r.number("x"), 1.0);
  ASSERT_TRUE(r.next());
  EXPECT_EQ(r.lineNumber(), 4u);
  EXPECT_TRUE(std::isnan(r.number("x")));
  EXPECT_EQ(r.error(), path + ":4: field 'x': cannot parse 'abc' as a number");
}

TEST(CsvTest, ReaderReportsMissingColumnsAndWrongFieldCount) {
  const auto path = writeTemp("csv_b.csv", "t,x\n0,1,2\n");
  CsvReader r(path);
  EXPECT_FALSE(r.requireColumns({"t", "y", "z"}));
  EXPECT_EQ(r.error(), path + ":1: header lacks column(s): y, z");
  CsvReader r2(path);
  EXPECT_FALSE(r2.next());
  EXPECT_EQ(r2.error(), path + ":2: expected 2 fields, got 3");
  CsvReader r3("/nonexistent.csv");
  EXPECT_EQ(r3.error(), "/nonexistent.csv: cannot open file");
}

TEST(CsvTest, EmptyFieldsAllowedOnlyWhenAsked) {
  const auto path = writeTemp("csv_c.csv", "t,x\n0,\n");
  CsvReader r(path);
  ASSERT_TRUE(r.next());
  EXPECT_TRUE(std::isnan(r.number("x", true)));
  EXPECT_TRUE(r.error().empty());
  r.number("x");
  EXPECT_EQ(r.error(), path + ":2: field 'x': empty (a number is required)");
}
