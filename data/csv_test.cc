#include "data/csv.h"

#include <gtest/gtest.h>

#include "data/error.h"

namespace kincal {
namespace {

TEST(CsvTest, FieldsColumnsQuotesAndComments) {
  const auto lines = TokenizeCsv(
      "# comment\n\na, b ,\"c,d\",\"e\"\"f\",\n  # indented comment\nx\n",
      "t.csv");
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].line, 3);
  ASSERT_EQ(lines[0].fields.size(), 5u);
  EXPECT_EQ(lines[0].fields[1].text, "b");
  EXPECT_EQ(lines[0].fields[1].column, 4);
  EXPECT_EQ(lines[0].fields[2].text, "c,d");
  EXPECT_EQ(lines[0].fields[3].text, "e\"f");
  EXPECT_EQ(lines[0].fields[4].text, "");
  EXPECT_EQ(lines[1].line, 5);
}

TEST(CsvTest, SemicolonSeparator) {
  const auto lines = TokenizeCsv("1,5;2\n", "t.csv", ';');
  ASSERT_EQ(lines[0].fields.size(), 2u);
  EXPECT_EQ(lines[0].fields[0].text, "1,5");
}

TEST(CsvTest, ParseFiniteDouble) {
  double v = 0;
  EXPECT_TRUE(ParseFiniteDouble("-1.5e2", &v));
  EXPECT_EQ(v, -150.0);
  EXPECT_FALSE(ParseFiniteDouble("", &v));
  EXPECT_FALSE(ParseFiniteDouble("nan", &v));
  EXPECT_FALSE(ParseFiniteDouble("1.5x", &v));
  EXPECT_FALSE(ParseFiniteDouble("inf", &v));
}

}  // namespace
}  // namespace kincal
