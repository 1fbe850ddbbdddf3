// A minimal log-log scatter plot written as SVG: series of (x, y) points,
// each drawn as a coloured polyline with markers and a legend.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace ldc::bench {

struct PlotSeries {
  std::string name;
  std::string colour;  // any SVG colour
  std::vector<std::pair<double, double>> points;  // (x, y), both > 0
  bool dashed = false;
};

inline bool write_loglog_svg(const std::string& path, const std::string& title, const std::string& x_label,
                             const std::string& y_label, const std::vector<PlotSeries>& series) {
  double x0 = 1e300, x1 = 0, y0 = 1e300, y1 = 0;
  for (const auto& s : series)
    for (auto [x, y] : s.points) {
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  if (!(x0 > 0 && y0 > 0 && x1 > x0 && y1 > y0)) return false;
  auto lx = [&](double v) { return std::floor(std::log10(v)); };
  double ax0 = lx(x0), ax1 = std::ceil(std::log10(x1)), ay0 = lx(y0), ay1 = std::ceil(std::log10(y1));
  const double W = 760, H = 520, L = 80, R = 200, T = 40, B = 60;
  auto px = [&](double x) { return L + (std::log10(x) - ax0) / (ax1 - ax0) * (W - L - R); };
  auto py = [&](double y) { return H - B - (std::log10(y) - ay0) / (ay1 - ay0) * (H - T - B); };
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return false;
  std::fprintf(f, "<svg xmlns='http://www.w3.org/2000/svg' width='%g' height='%g' font-family='sans-serif' font-size='12'>\n", W, H);
  std::fprintf(f, "<rect width='100%%' height='100%%' fill='white'/>\n<text x='%g' y='22' font-size='15'>%s</text>\n", L, title.c_str());
  for (double e = ax0; e <= ax1; ++e) {
    std::fprintf(f, "<line x1='%g' y1='%g' x2='%g' y2='%g' stroke='#ddd'/><text x='%g' y='%g' text-anchor='middle'>1e%g</text>\n",
                 px(std::pow(10, e)), T, px(std::pow(10, e)), H - B, px(std::pow(10, e)), H - B + 18, e);
  }
  for (double e = ay0; e <= ay1; ++e) {
    std::fprintf(f, "<line x1='%g' y1='%g' x2='%g' y2='%g' stroke='#ddd'/><text x='%g' y='%g' text-anchor='end'>1e%g</text>\n",
                 L, py(std::pow(10, e)), W - R, py(std::pow(10, e)), L - 6, py(std::pow(10, e)) + 4, e);
  }
  std::fprintf(f, "<text x='%g' y='%g' text-anchor='middle'>%s</text>\n", (L + W - R) / 2, H - 15, x_label.c_str());
  std::fprintf(f, "<text x='18' y='%g' transform='rotate(-90 18 %g)' text-anchor='middle'>%s</text>\n", (T + H - B) / 2,
               (T + H - B) / 2, y_label.c_str());
  for (size_t i = 0; i < series.size(); ++i) {
    const PlotSeries& s = series[i];
    std::string pts;
    for (auto [x, y] : s.points) pts += std::to_string(px(x)) + "," + std::to_string(py(y)) + " ";
    std::fprintf(f, "<polyline points='%s' fill='none' stroke='%s' stroke-width='1.5'%s/>\n", pts.c_str(), s.colour.c_str(),
                 s.dashed ? " stroke-dasharray='5,3'" : "");
    for (auto [x, y] : s.points) std::fprintf(f, "<circle cx='%g' cy='%g' r='3' fill='%s'/>\n", px(x), py(y), s.colour.c_str());
    double ly = T + 16 * double(i);
    std::fprintf(f, "<line x1='%g' y1='%g' x2='%g' y2='%g' stroke='%s' stroke-width='2'%s/><text x='%g' y='%g'>%s</text>\n",
                 W - R + 10, ly, W - R + 30, ly, s.colour.c_str(), s.dashed ? " stroke-dasharray='5,3'" : "", W - R + 35, ly + 4,
                 s.name.c_str());
  }
  std::fprintf(f, "</svg>\n");
  return std::fclose(f) == 0;
}

}  // namespace ldc::bench
