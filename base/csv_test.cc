#include "base/csv.h"

#include <gtest/gtest.h>

#include "base/error.h"

namespace daylit {
namespace {

TEST(CsvTest, QuotedFieldsWithCommasQuotesAndNewlines) {
  const CsvTable t = ParseCsv("a,b,c\r\n1,\"x, \"\"y\"\"\",3\n\n4,\"two\nlines\",6\n", "in.csv");
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[0][1], "x, \"y\"");
  EXPECT_EQ(t.rows[1][1], "two\nlines");
  EXPECT_EQ(t.line_numbers[0], 2);
  EXPECT_EQ(t.line_numbers[1], 4);
  EXPECT_EQ(t.Column("c"), 2);
  EXPECT_EQ(t.Column("d"), -1);
  EXPECT_EQ(CsvField("x, \"y\""), "\"x, \"\"y\"\"\"");
  EXPECT_EQ(CsvField("plain"), "plain");
}

TEST(CsvTest, ErrorsNameFileAndLine) {
  try {
    ParseCsv("a,b\n1,2\n3\n", "in.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "in.csv:3: 1 fields, but the header has 2");
  }
  EXPECT_THROW(ParseCsv("a,b\n1,\"2\n", "in.csv"), InputError);
  EXPECT_THROW(ParseCsv("\n\n", "in.csv"), InputError);
  const CsvTable t = ParseCsv("a\n1\n", "in.csv");
  try {
    t.RequireColumn("lat_deg");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "in.csv: missing column 'lat_deg'");
  }
}

TEST(CsvTest, FiniteNumbersOnly) {
  EXPECT_DOUBLE_EQ(ParseFiniteDouble(" -105.1786 ", "w"), -105.1786);
  EXPECT_DOUBLE_EQ(ParseFiniteDouble("+1e3", "w"), 1000.0);
  for (const char* bad : {"nan", "inf", "", "1.2.3", "12abc", "-"}) {
    EXPECT_THROW(ParseFiniteDouble(bad, "w"), InputError) << bad;
  }
}

}  // namespace
}  // namespace daylit
