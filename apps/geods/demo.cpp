#include "demo.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <memory>
#include <string_view>

#include "geods/core/error.hpp"
#include "geods/io/svg.hpp"

namespace geods::cli {

namespace {

constexpr std::array<std::string_view, 14> kModuleOrder = {
    "core", "io", "spatial", "dynamic", "terrain", "iso", "ray", "bsp", "bvh", "collide", "voronoi", "texture",
    "shape", "field"};

std::size_t module_rank(const std::string& module) {
  const auto it = std::find(kModuleOrder.begin(), kModuleOrder.end(), module);
  return std::size_t(it - kModuleOrder.begin());
}

std::vector<std::unique_ptr<DemoStep>>& steps() {
  static std::vector<std::unique_ptr<DemoStep>> all;
  return all;
}

constexpr std::string_view kStyle = R"(
body { font-family: system-ui, sans-serif; max-width: 1100px; margin: 2em auto; padding: 0 1em; color: #222; }
h1 { margin-bottom: 0.2em; } h2 { border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 2em; }
.module { color: #888; font-weight: normal; font-size: 0.8em; }
figure { display: inline-block; margin: 0.5em; vertical-align: top; }
figure img { max-width: 520px; border: 1px solid #ddd; background: white; }
figcaption { font-size: 0.9em; color: #555; max-width: 520px; }
table { border-collapse: collapse; margin: 0.5em 0; } td, th { padding: 2px 10px; text-align: left; border-bottom: 1px solid #eee; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
.error { color: #b00; font-weight: bold; } .ok { color: #080; }
nav a { margin-right: 1em; }
)";

}  // namespace

bool register_demo_step(DemoStep step) {
  if (module_rank(step.module) == kModuleOrder.size()) throw Error("demo step " + step.name + ": unknown module " + step.module);
  steps().push_back(std::make_unique<DemoStep>(std::move(step)));
  return true;
}

std::vector<const DemoStep*> demo_steps() {
  std::vector<const DemoStep*> out;
  for (const auto& s : steps()) out.push_back(s.get());
  std::stable_sort(out.begin(), out.end(), [](const DemoStep* a, const DemoStep* b) {
    const auto ra = module_rank(a->module), rb = module_rank(b->module);
    return ra != rb ? ra < rb : a->name < b->name;
  });
  return out;
}

void write_demo_gallery(const std::filesystem::path& out_dir, const std::vector<DemoOutcome>& outcomes) {
  std::string html = fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>geods demo</title>"
      "<style>{}</style></head><body>\n<h1>geods demo</h1>\n"
      "<p>Every capability of geods run on the data sets of <code>data/</code> (see data/PROVENANCE.md). "
      "Timings exclude file I/O unless stated.</p>\n<nav>",
      kStyle);
  for (const DemoOutcome& o : outcomes) {
    html += fmt::format("<a href=\"#{0}-{1}\">{0}/{1}</a>", io::xml_escape(o.step->module), io::xml_escape(o.step->name));
  }
  html += "</nav>\n";
  for (const DemoOutcome& o : outcomes) {
    const DemoResult& r = o.result;
    html += fmt::format("<section id=\"{0}-{1}\"><h2>{2} <span class=\"module\">{0}/{1}</span></h2>\n",
                        io::xml_escape(o.step->module), io::xml_escape(o.step->name), io::xml_escape(o.step->title));
    if (!o.error.empty()) html += fmt::format("<p class=\"error\">failed: {}</p>\n", io::xml_escape(o.error));
    if (!r.text.empty()) html += fmt::format("<p>{}</p>\n", io::xml_escape(r.text));
    for (const auto& f : r.figures) {
      html += fmt::format("<figure><a href=\"{0}\"><img src=\"{0}\" alt=\"{1}\"></a><figcaption>{1}</figcaption></figure>\n",
                          io::xml_escape(f.file), io::xml_escape(f.caption));
    }
    if (!r.files.empty()) {
      html += "<p>Files: ";
      for (const auto& f : r.files) html += fmt::format("<a href=\"{}\">{}</a> ", io::xml_escape(f.file), io::xml_escape(f.caption));
      html += "</p>\n";
    }
    if (!r.stats.empty()) {
      html += "<table>\n";
      for (const auto& [name, value] : r.stats) {
        html += fmt::format("<tr><th>{}</th><td>{}</td></tr>\n", io::xml_escape(name), io::xml_escape(value));
      }
      html += "</table>\n";
    }
    html += "<table>\n";
    for (const auto& [name, seconds] : r.timings) {
      html += fmt::format("<tr><th>{}</th><td class=\"num\">{:.4f} s</td></tr>\n", io::xml_escape(name), seconds);
    }
    html += fmt::format("<tr><th>step total</th><td class=\"num\">{:.4f} s</td></tr>\n</table>\n</section>\n", o.seconds);
  }
  html += "</body></html>\n";
  std::ofstream out(out_dir / "index.html");
  out << html;
  if (!out) throw Error((out_dir / "index.html").string() + ": cannot write");
}

}  // namespace geods::cli
