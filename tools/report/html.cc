// SPDX-License-Identifier: MIT
#include "report/html.h"

#include <sstream>

#include "report/svg.h"

namespace cbrdf::report {
namespace {

constexpr const char* kStyle = R"(
body { font-family: sans-serif; max-width: 1280px; margin: 1em auto; padding: 0 1em; color: #222; }
h1 { font-size: 1.6em; } h2 { font-size: 1.2em; margin-top: 1.6em; } h3 { margin-bottom: 0.3em; }
p.note { color: #555; max-width: 60em; }
p.answer { max-width: 60em; margin: 0.4em 0; }
div.scroll { overflow-x: auto; }
table { border-collapse: collapse; font-size: 0.85em; }
th, td { border: 1px solid #ccc; padding: 2px 6px; text-align: right; white-space: nowrap; }
th { background: #f0f0f0; } td.l { text-align: left; }
figure { display: inline-block; margin: 0.5em 1em 0.5em 0; vertical-align: top; }
figcaption { font-size: 0.85em; color: #555; max-width: 900px; }
.spheres img { width: 200px; height: 200px; image-rendering: pixelated; }
nav a { margin-right: 1em; white-space: nowrap; }
)";

constexpr const char* kScript = R"(
window.addEventListener('load', function () {
  var images = Array.prototype.slice.call(document.images);
  var broken = images.filter(function (i) { return !(i.complete && i.naturalWidth > 0); });
  document.body.setAttribute('data-images', String(images.length));
  document.body.setAttribute('data-images-broken', String(broken.length));
  document.body.setAttribute('data-loaded', broken.length === 0 ? 'ok' : 'broken');
});
)";

void figure(std::ostringstream& out, const Figure& f) {
  out << "<figure><img src=\"" << xml_escape(f.file) << "\" alt=\"" << xml_escape(f.caption)
      << "\"><figcaption>" << xml_escape(f.caption) << "</figcaption></figure>\n";
}

}  // namespace

std::string sphere_file(const std::string& material, const char* which) {
  return "sphere_" + file_stem(material) + "_" + which + ".png";
}

std::string report_html(const std::vector<MaterialResult>& results, const Settings& st,
                        const std::vector<TextTable>& tables, const std::vector<Figure>& figures,
                        const std::string& summary, const std::string& answer) {
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
      << "<title>cbrdf report</title>\n<style>" << kStyle << "</style>\n<script>" << kScript
      << "</script></head>\n<body>\n<h1>cbrdf report</h1>\n";
  // The answer first: one paragraph and the frontier figure, on the first screen.
  if (!answer.empty()) out << "<p class=\"answer\">" << xml_escape(answer) << "</p>\n";
  for (const Figure& f : figures) {
    if (f.file == kLeadFigure) figure(out, f);
  }
  out << "<p class=\"note\">" << xml_escape(summary) << "</p>\n<nav>";
  for (const TextTable& t : tables) {
    const std::string name = t.nav.empty() ? t.title.substr(0, t.title.find(':')) : t.nav;
    out << "<a href=\"#" << t.id << "\">" << xml_escape(name) << "</a>";
  }
  out << "<a href=\"#figures\">Figures</a><a href=\"#materials\">Materials</a></nav>\n";
  for (const TextTable& t : tables) out << to_html(t);
  out << "<h2 id=\"figures\">Figures</h2>\n";
  for (const Figure& f : figures) {
    if (f.material.empty() && f.file != kLeadFigure) figure(out, f);
  }
  out << "<h2 id=\"materials\">Materials</h2>\n<p class=\"note\">Sphere renders lit at "
      << kImageLightDeg << " degrees (paper's Figure 4): the input, the decoded "
      << xml_escape(st.sweep.primary().label())
      << " file, and their difference after tone mapping (viridis; yellow = " << kDifferenceScale
      << " or more, the same scale for every material).</p>\n";
  for (const MaterialResult& m : results) {
    out << "<h3 id=\"m-" << xml_escape(file_stem(m.name)) << "\">" << xml_escape(m.name)
        << "</h3>\n<div class=\"spheres\">\n";
    const char* which[] = {"reference", "decoded", "difference"};
    const std::string captions[] = {"input", "decoded " + m.decoded_label, "difference"};
    for (int i = 0; i < 3; ++i) {
      out << "<figure><img src=\"" << xml_escape(sphere_file(m.name, which[i])) << "\" alt=\""
          << xml_escape(m.name + " " + captions[i]) << "\"><figcaption>" << xml_escape(captions[i])
          << "</figcaption></figure>\n";
    }
    out << "</div>\n";
    for (const Figure& f : figures) {
      if (f.material == m.name) figure(out, f);
    }
  }
  out << "</body></html>\n";
  return out.str();
}

}  // namespace cbrdf::report
