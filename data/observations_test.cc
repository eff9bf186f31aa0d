#include "data/observations.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "data/error.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

const std::vector<std::string> kJoints = {"j1", "j2", "j3", "j4", "j5"};

const char* kGood =
    "# a comment\n"
    "pose,j1,j2,j3,j4,j5,x,y,z,fixed_point,t\n"
    "0,78.4602,36.0462,95.4866,153.0275,-45.1143,1.5,2.5,3.5,hole_0,0.0\n"
    "1,70,30,90,150,-40,,,,hole_0,1.5\n"
    "p2,71,31,91,151,-41,4,5,6,,\n";

std::string ErrorOf(const std::string& text) {
  try {
    ParseObservationsCsv(text, "o.csv", kJoints);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ObservationsTest, ReadsAllColumns) {
  const Observations obs = ParseObservationsCsv(kGood, "o.csv", kJoints);
  ASSERT_EQ(obs.rows.size(), 3u);
  EXPECT_EQ(obs.rows[0].pose, "0");
  EXPECT_DOUBLE_EQ(obs.rows[0].q[4], -45.1143);
  EXPECT_TRUE(obs.rows[0].has_point);
  EXPECT_DOUBLE_EQ(obs.rows[0].p_in_meas.z(), 3.5);
  EXPECT_FALSE(obs.rows[1].has_point);
  EXPECT_EQ(obs.rows[1].fixed_point, "hole_0");
  EXPECT_DOUBLE_EQ(obs.rows[1].t_s, 1.5);
  EXPECT_TRUE(obs.rows[2].fixed_point.empty());
  EXPECT_FALSE(obs.rows[2].HasTime());
  EXPECT_EQ(obs.rows[2].line, 5);
  EXPECT_EQ(obs.CountWithPoints(), 2);
}

TEST(ObservationsTest, ColumnsInAnyOrderMapToRobotOrder) {
  const Observations obs = ParseObservationsCsv(
      "j5,j4,pose,j3,j2,j1\n5,4,a,3,2,1\n", "o.csv", kJoints);
  EXPECT_EQ(obs.rows[0].q, (std::vector<double>{1, 2, 3, 4, 5}));
}

TEST(ObservationsTest, AcceptsCrlfAndBom) {
  std::string crlf;
  for (char c : std::string(kGood)) {
    if (c == '\n') crlf += '\r';
    crlf += c;
  }
  const Observations a = ParseObservationsCsv(kGood, "o.csv", kJoints);
  const Observations b =
      ParseObservationsCsv("\xEF\xBB\xBF" + crlf, "o.csv", kJoints);
  ASSERT_EQ(a.rows.size(), b.rows.size());
  for (size_t i = 0; i < a.rows.size(); ++i) {
    EXPECT_EQ(a.rows[i].pose, b.rows[i].pose);
    EXPECT_EQ(a.rows[i].q, b.rows[i].q);
    EXPECT_EQ(a.rows[i].fixed_point, b.rows[i].fixed_point);
  }
}

TEST(ObservationsTest, RejectsEveryRuleWithPosition) {
  const std::string h = "pose,j1,j2,j3,j4,j5,x,y,z\n";
  EXPECT_THAT(ErrorOf(""), HasSubstr("o.csv: empty file"));
  EXPECT_THAT(ErrorOf("# only a comment\n"), HasSubstr("empty file"));
  EXPECT_THAT(ErrorOf(h), HasSubstr("no observation rows"));
  EXPECT_THAT(
      ErrorOf(h + "0,1,2,3,4,5,1,2\n"),
      HasSubstr("o.csv:2:16: expected 9 columns as in the header, got 8"));
  EXPECT_THAT(ErrorOf(h + "0,1,2,3,4,5,1,2,3,9\n"),
              HasSubstr("o.csv:2:19: expected 9 columns"));
  EXPECT_THAT(ErrorOf(h + "0,1,2,x3,4,5,1,2,3\n"),
              HasSubstr("o.csv:2:7: column 'j3': expected a finite number"));
  EXPECT_THAT(ErrorOf(h + "0,1,2,nan,4,5,1,2,3\n"),
              HasSubstr("o.csv:2:7: column 'j3'"));
  EXPECT_THAT(ErrorOf(h + "0,1,2,inf,4,5,1,2,3\n"), HasSubstr("finite"));
  EXPECT_THAT(ErrorOf(h + "0,1,2,,4,5,1,2,3\n"), HasSubstr("o.csv:2:7:"));
  EXPECT_THAT(ErrorOf(h + "0,1,2,3,4,5,1,NaN,3\n"),
              HasSubstr("o.csv:2:15: column 'y'"));
  EXPECT_THAT(ErrorOf("pose,j1,j2,j3,j4,j6\n0,1,2,3,4,5\n"),
              HasSubstr("o.csv:1:18: unknown column 'j6'"));
  EXPECT_THAT(ErrorOf("pose,j1,j2,j3,j4\n0,1,2,3,4\n"),
              HasSubstr("header has no column for joint 'j5'"));
  EXPECT_THAT(ErrorOf("j1,j2,j3,j4,j5\n1,2,3,4,5\n"),
              HasSubstr("no 'pose' column"));
  EXPECT_THAT(ErrorOf("pose,j1,j2,j3,j4,j5,j2\n0,1,2,3,4,5,6\n"),
              HasSubstr("o.csv:1:21: duplicate column 'j2'"));
  EXPECT_THAT(ErrorOf(h + "0,1,2,3,4,5,1,2,3\n0,1,2,3,4,5,1,2,3\n"),
              HasSubstr("o.csv:3:1: duplicate pose id '0'"));
  EXPECT_THAT(ErrorOf(h + "0,1,2,3,4,5,1,,3\n"),
              HasSubstr("o.csv:2:13: x, y, z: give all three"));
  EXPECT_THAT(ErrorOf("pose,j1,j2,j3,j4,j5,x,y\n0,1,2,3,4,5,1,2\n"),
              HasSubstr("only some of x, y, z"));
  EXPECT_THAT(ErrorOf(h + ",1,2,3,4,5,1,2,3\n"), HasSubstr("empty pose id"));
  EXPECT_THAT(ErrorOf("pose,j1,j2,j3,j4,j5,t\n0,1,2,3,4,5,noon\n"),
              HasSubstr("column 't'"));
  EXPECT_THAT(ErrorOf(h + "\"0,1,2,3,4,5,1,2,3\n"),
              HasSubstr("unterminated quoted field"));
}

TEST(ObservationsTest, FormatThenParseIsIdentity) {
  const Observations obs = ParseObservationsCsv(kGood, "o.csv", kJoints);
  const Observations back =
      ParseObservationsCsv(FormatObservationsCsv(obs), "back.csv", kJoints);
  ASSERT_EQ(back.rows.size(), obs.rows.size());
  for (size_t i = 0; i < obs.rows.size(); ++i) {
    EXPECT_EQ(back.rows[i].pose, obs.rows[i].pose);
    EXPECT_EQ(back.rows[i].q, obs.rows[i].q);
    EXPECT_EQ(back.rows[i].has_point, obs.rows[i].has_point);
    EXPECT_EQ(back.rows[i].p_in_meas, obs.rows[i].p_in_meas);
    EXPECT_EQ(back.rows[i].fixed_point, obs.rows[i].fixed_point);
    EXPECT_EQ(back.rows[i].HasTime(), obs.rows[i].HasTime());
  }
}

// Spec v2: optional temp_c column (deg C), empty cells allowed, kept on
// output.
TEST(ObservationsTest, ReadsAndWritesTempC) {
  const Observations obs = ParseObservationsCsv(
      "pose,j1,j2,j3,j4,j5,x,y,z,temp_c\n"
      "0,1,2,3,4,5,1,2,3,21.5\n"
      "1,1,2,3,4,6,1,2,3,\n",
      "o.csv", kJoints);
  ASSERT_EQ(obs.rows.size(), 2u);
  EXPECT_DOUBLE_EQ(obs.rows[0].temp_c, 21.5);
  EXPECT_FALSE(obs.rows[1].HasTemp());
  EXPECT_TRUE(obs.AnyTemp());
  const std::string text = FormatObservationsCsv(obs);
  EXPECT_THAT(text, HasSubstr(",temp_c\n"));
  const Observations back = ParseObservationsCsv(text, "back.csv", kJoints);
  EXPECT_DOUBLE_EQ(back.rows[0].temp_c, 21.5);
  EXPECT_FALSE(back.rows[1].HasTemp());
  EXPECT_THAT(ErrorOf("pose,j1,j2,j3,j4,j5,temp_c\n0,1,2,3,4,5,warm\n"),
              HasSubstr("column 'temp_c'"));
  EXPECT_THAT(ErrorOf("pose,j1,j2,j3,j4,j5,temp_c\n0,1,2,3,4,5,-300\n"),
              HasSubstr("column 'temp_c'"));
}

// Spec v3: optional series column; labels in first-seen order, rows per
// series, kept on output; a file without it is one unlabelled series.
TEST(ObservationsTest, ReadsAndWritesSeries) {
  const Observations obs = ParseObservationsCsv(
      "pose,j1,j2,j3,j4,j5,x,y,z,series\n"
      "0,1,2,3,4,5,1,2,3,C\n"
      "1,1,2,3,4,6,1,2,3,B\n"
      "2,1,2,3,4,7,1,2,3,C\n"
      "3,1,2,3,4,8,1,2,3,\n",
      "o.csv", kJoints);
  ASSERT_EQ(obs.rows.size(), 4u);
  EXPECT_EQ(obs.rows[0].series, "C");
  EXPECT_EQ(obs.rows[1].series, "B");
  EXPECT_EQ(obs.rows[3].series, "");
  EXPECT_TRUE(obs.AnySeriesLabel());
  EXPECT_EQ(obs.SeriesNames(), (std::vector<std::string>{"C", "B", ""}));
  EXPECT_EQ(obs.SeriesRows("C"), (std::vector<int>{0, 2}));
  EXPECT_EQ(obs.SeriesRows("B"), (std::vector<int>{1}));
  EXPECT_TRUE(obs.SeriesRows("A").empty());
  const std::string text = FormatObservationsCsv(obs);
  EXPECT_THAT(text, HasSubstr(",x,y,z,series\n"));
  const Observations back = ParseObservationsCsv(text, "back.csv", kJoints);
  ASSERT_EQ(back.rows.size(), 4u);
  for (size_t i = 0; i < obs.rows.size(); ++i)
    EXPECT_EQ(back.rows[i].series, obs.rows[i].series);
  EXPECT_EQ(Subset(obs, {1, 2}).SeriesNames(),
            (std::vector<std::string>{"B", "C"}));

  const Observations plain = ParseObservationsCsv(kGood, "o.csv", kJoints);
  EXPECT_FALSE(plain.AnySeriesLabel());
  EXPECT_EQ(plain.SeriesNames(), (std::vector<std::string>{""}));
  EXPECT_EQ(plain.SeriesRows("").size(), 3u);
  EXPECT_THAT(FormatObservationsCsv(plain), Not(HasSubstr("series")));
  EXPECT_THAT(ErrorOf("pose,j1,j2,j3,j4,j5,series,series\n0,1,2,3,4,5,a,a\n"),
              HasSubstr("duplicate column 'series'"));
}

// Commands fitting one frame refuse 2+ series with the series named, at the
// first row of the second series.
TEST(ObservationsTest, RequireOneSeriesNamesTheSeries) {
  const std::string h = "pose,j1,j2,j3,j4,j5,series\n";
  EXPECT_NO_THROW(RequireOneSeries(
      ParseObservationsCsv(h + "0,1,2,3,4,5,B\n1,1,2,3,4,6,B\n", "o.csv",
                           kJoints),
      "calibrate"));
  EXPECT_NO_THROW(RequireOneSeries(
      ParseObservationsCsv(kGood, "o.csv", kJoints), "calibrate"));
  const Observations two = ParseObservationsCsv(
      h + "0,1,2,3,4,5,B\n1,1,2,3,4,6,B\n2,1,2,3,4,7,C\n", "o.csv", kJoints);
  try {
    RequireOneSeries(two, "calibrate");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 4);
    EXPECT_THAT(e.what(), HasSubstr("o.csv:4: the rows belong to 2 series"));
    EXPECT_THAT(e.what(), HasSubstr("'B' (2 rows), 'C' (1 rows)"));
    EXPECT_THAT(e.what(), HasSubstr("`kincal calibrate`"));
    EXPECT_THAT(e.what(), HasSubstr("`kincal evaluate` registers one frame"));
  }
}

}  // namespace
}  // namespace kincal
