#include "report/html.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace kincal {
namespace {

// Print-friendly, no web fonts, figures scale with the page (zoom = vector).
const char kStyle[] = R"CSS(
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;max-width:1100px;margin:0 auto;padding:1em 2em;color:#222;line-height:1.45}
h1{font-size:1.6em;margin-bottom:.2em} h2{border-bottom:2px solid #ddd;padding-bottom:.2em;margin-top:1.6em}
nav{font-size:.9em;color:#555} nav a{margin-right:.8em}
.verdict{font-size:1.15em;background:#f4f8fb;border-left:5px solid #1f77b4;padding:.6em 1em}
table{border-collapse:collapse;font-size:.88em;margin:.6em 0} th,td{border:1px solid #ccc;padding:2px 8px;text-align:left} td.num{text-align:right}
th{background:#f0f0f0}
figure{margin:1em 0;page-break-inside:avoid;break-inside:avoid} figure svg{max-width:100%;height:auto;border:1px solid #eee}
figure.row{display:flex;flex-wrap:wrap;gap:6px;align-items:flex-start}
figure.row figcaption{flex-basis:100%}
figcaption{font-size:.9em;color:#444}
code,pre{font-size:.85em;background:#f6f6f6} pre{padding:.5em;white-space:pre-wrap;word-break:break-all}
.note{color:#8a5a00}
.verdict p.pass{font-weight:bold;color:#1a6b1a} .verdict p.fail{font-weight:bold;color:#a01010} .verdict p.undecided{font-weight:bold;color:#8a5a00}
@media print{nav{display:none} body{max-width:none;padding:0} h2{page-break-after:avoid}}
)CSS";

// Marks the page with how many figures drew (a non-empty bounding box after
// layout) and reports any that did not on the console.
const char kScript[] = R"JS(
window.addEventListener('load',function(){
  var figs=document.querySelectorAll('svg.plot'),ok=0;
  figs.forEach(function(s){var b=s.getBBox();
    if(b.width>0&&b.height>0&&s.querySelectorAll('circle,polyline,rect,line').length>3){ok++;s.setAttribute('data-drawn','yes');}
    else{console.error('kincal report: figure '+s.id+' did not draw');}});
  document.body.setAttribute('data-figures',ok+'/'+figs.length);
});
)JS";

}  // namespace

std::string Fmt(double v, int digits) {
  if (!std::isfinite(v)) return "-";
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%.*g", digits, v);
  return buf;
}

void HtmlReport::Section(const std::string& id, const std::string& heading) {
  ids_.push_back(id);
  headings_.push_back(heading);
  body_ += "<section id='" + XmlEscape(id) + "'><h2>" + XmlEscape(heading) +
           "</h2>\n";
}

void HtmlReport::Paragraph(const std::string& text) {
  body_ += "<p>" + XmlEscape(text) + "</p>\n";
}

void HtmlReport::Raw(const std::string& html) { body_ += html + "\n"; }

void HtmlReport::Bullets(const std::vector<std::string>& items) {
  body_ += "<ul>";
  for (const auto& i : items) body_ += "<li>" + XmlEscape(i) + "</li>";
  body_ += "</ul>\n";
}

void HtmlReport::Table(const std::vector<std::string>& header,
                       const std::vector<std::vector<std::string>>& rows) {
  body_ += "<table><tr>";
  for (const auto& h : header) body_ += "<th>" + XmlEscape(h) + "</th>";
  body_ += "</tr>\n";
  for (const auto& r : rows) {
    body_ += "<tr>";
    for (const auto& c : r) {
      // Numbers right-aligned, words left.
      char* end = nullptr;
      std::strtod(c.c_str(), &end);
      const bool num = (!c.empty() && end && *end == '\0') || c == "-";
      body_ += (num ? "<td class='num'>" : "<td>") + XmlEscape(c) + "</td>";
    }
    body_ += "</tr>\n";
  }
  body_ += "</table>\n";
}

void HtmlReport::Figure(const Plot& plot, const std::string& caption) {
  FigureRow({plot}, caption);
}

void HtmlReport::FigureRow(const std::vector<Plot>& plots,
                           const std::string& caption) {
  // Plots are shown at their own width when the page has room (one type
  // scale for every figure), side by side while they fit.
  const bool grid = plots.size() > 1 || plots[0].width < 600;
  body_ += grid ? "<figure class='row'>\n" : "<figure>\n";
  for (const Plot& p : plots) {
    body_ += FormatInlineSvg(p, "fig" + std::to_string(++figures_));
  }
  body_ += "<figcaption>" + XmlEscape(caption) + "</figcaption></figure>\n";
}

std::string HtmlReport::Page(const std::string& footer) const {
  std::string nav = "<nav>";
  for (size_t i = 0; i < ids_.size(); ++i) {
    nav += "<a href='#" + XmlEscape(ids_[i]) + "'>" + XmlEscape(headings_[i]) +
           "</a>";
  }
  nav += "</nav>\n";
  std::string body = body_;
  // Close every open section (each Section() opened one).
  std::string closed;
  size_t open = 0;
  for (size_t at = body.find("<section"); at != std::string::npos;
       at = body.find("<section", at + 1)) {
    if (open > 0) {
      body.insert(at, "</section>\n");
      at += 11;
    }
    ++open;
  }
  if (open > 0) body += "</section>\n";
  return "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>\n"
         "<meta name='viewport' content='width=device-width, "
         "initial-scale=1'>\n<title>" +
         XmlEscape(title_) + "</title>\n<style>" + kStyle +
         "</style>\n</head><body>\n<h1>" + XmlEscape(title_) + "</h1>\n" + nav +
         body + "<footer><p><small>" + XmlEscape(footer) +
         "</small></p></footer>\n<script>" + kScript +
         "</script>\n</body></html>\n";
}

}  // namespace kincal
