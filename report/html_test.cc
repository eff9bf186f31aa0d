// The page builder: escaping, sections closed, numbers right-aligned, plots
// inlined at their own width, nothing loaded from outside.

#include "report/html.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace kincal {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

size_t Count(const std::string& s, const std::string& what) {
  size_t n = 0;
  for (size_t at = s.find(what); at != std::string::npos;
       at = s.find(what, at + 1)) {
    ++n;
  }
  return n;
}

TEST(HtmlTest, SectionsAreClosedEscapedAndListed) {
  HtmlReport page("t <1>");
  page.Section("a", "First & only");
  page.Paragraph("x < y");
  page.Section("b", "Second");
  page.Table({"name", "value"}, {{"j1", "0.5"}, {"j2", "-"}});
  const std::string html = page.Page("foot");
  EXPECT_EQ(page.sections(), (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(Count(html, "<section"), 2u);
  EXPECT_EQ(Count(html, "</section>"), 2u);
  EXPECT_THAT(html, HasSubstr("First &amp; only"));
  EXPECT_THAT(html, HasSubstr("<p>x &lt; y</p>"));
  EXPECT_THAT(html, HasSubstr("<td class='num'>0.5</td>"));
  EXPECT_THAT(html, HasSubstr("<td>j1</td>"));
  EXPECT_THAT(html, HasSubstr("<a href='#b'>Second</a>"));
  EXPECT_THAT(html, Not(HasSubstr("https://")));
}

TEST(HtmlTest, FiguresAreNumberedAndShownAtTheirOwnWidth) {
  HtmlReport page("t");
  page.Section("s", "S");
  Plot p;
  p.width = 500;
  p.height = 300;
  p.series.push_back({"a", {0, 1}, {0, 1}});
  page.FigureRow({p, p}, "two");
  page.Figure(p, "one");
  EXPECT_EQ(page.figures(), 3);
  const std::string html = page.Page("");
  EXPECT_THAT(html, HasSubstr("id='fig3'"));
  EXPECT_THAT(html, HasSubstr("width='500'"));
  EXPECT_THAT(html, HasSubstr("<figcaption>two</figcaption>"));
}

TEST(HtmlTest, FmtRoundsToSignificantDigits) {
  EXPECT_EQ(Fmt(0.123456, 3), "0.123");
  EXPECT_EQ(Fmt(1234.5, 2), "1.2e+03");
  EXPECT_EQ(Fmt(NAN), "-");
}

}  // namespace
}  // namespace kincal
