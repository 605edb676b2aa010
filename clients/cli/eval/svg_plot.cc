// Line plots of accuracy and modeling time against the number of tubes (hand-written SVG).
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "clients/cli/eval/eval_report.h"
#include "clients/cli/eval/svg_util.h"

namespace tubepick::cli {
namespace {

constexpr const char* kFont = "font-family=\"DejaVu Sans, Arial, Helvetica, sans-serif\"";

struct Series {
  std::string name;
  std::string colour;
  std::function<double(const EvaluationAggregate&)> value;
  bool dashed = false;
};

// A "nice" step for about `ticks` intervals over [0, top].
double NiceStep(double top, int ticks) {
  const double raw = top / ticks;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * mag >= raw) return m * mag;
  return 10.0 * mag;
}

std::string Chart(double ox, double oy, double w, double h, const std::string& title,
                  const std::string& y_label, double y_min, double y_max, const std::string& y_format,
                  const std::vector<EvaluationAggregate>& rows, const std::vector<Series>& series) {
  std::string out;
  const double left = 70, right = 10, top = 34 + 15.0 * series.size(), bottom = 50;
  const double pw = w - left - right, ph = h - top - bottom;
  const double x0 = ox + left, y0 = oy + top;
  const double n_min = rows.front().tube_count, n_max = rows.back().tube_count;
  auto X = [&](double n) { return n_max > n_min ? x0 + (n - n_min) / (n_max - n_min) * pw : x0 + pw / 2; };
  auto Y = [&](double v) { return y0 + ph - (std::clamp(v, y_min, y_max) - y_min) / (y_max - y_min) * ph; };
  out += fmt::format("<text x=\"{}\" y=\"{}\" {} font-size=\"16\" font-weight=\"bold\">{}</text>\n",
                     ox + left, oy + 22, kFont, XmlEscape(title));
  const double step = NiceStep(y_max - y_min, 5);
  for (double v = y_min; v <= y_max + 1e-9; v += step) {
    out += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#e3e3e3\"/>\n",
                       x0, Y(v), x0 + pw, Y(v));
    out += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" {} font-size=\"12\" text-anchor=\"end\">{}</text>\n",
                       x0 - 6, Y(v) + 4, kFont, fmt::format(fmt::runtime(y_format), v));
  }
  for (const EvaluationAggregate& r : rows) {
    out +=
        fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" {} font-size=\"12\" text-anchor=\"middle\">{}</text>\n",
                    X(r.tube_count), y0 + ph + 18, kFont, r.tube_count);
  }
  out += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#444\"/>\n",
                     x0, y0, pw, ph);
  out += fmt::format(
      "<text x=\"{:.1f}\" y=\"{:.1f}\" {} font-size=\"13\" text-anchor=\"middle\">number of tubes in "
      "the bin</text>\n",
      x0 + pw / 2, y0 + ph + 38, kFont);
  out += fmt::format(
      "<text transform=\"translate({:.1f},{:.1f}) rotate(-90)\" {} font-size=\"13\" "
      "text-anchor=\"middle\">{}</text>\n",
      ox + 16, y0 + ph / 2, kFont, XmlEscape(y_label));
  double legend_y = oy + 40;  // legend between the title and the plot area
  for (const Series& s : series) {
    std::string points;
    for (const EvaluationAggregate& r : rows)
      points += fmt::format("{:.1f},{:.1f} ", X(r.tube_count), Y(s.value(r)));
    out += fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"2.2\" {} points=\"{}\"/>\n",
                       s.colour, s.dashed ? "stroke-dasharray=\"6 4\"" : "", points);
    for (const EvaluationAggregate& r : rows) {
      out += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"3\" fill=\"{}\"/>\n", X(r.tube_count),
                         Y(s.value(r)), s.colour);
    }
    out += fmt::format(
        "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"{}\" "
        "stroke-width=\"2.2\" {}/>\n",
        x0 + 10, legend_y, x0 + 32, legend_y, s.colour, s.dashed ? "stroke-dasharray=\"6 4\"" : "");
    out += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" {} font-size=\"12\">{}</text>\n", x0 + 38,
                       legend_y + 4, kFont, XmlEscape(s.name));
    legend_y += 15;
  }
  return out;
}

double StageMean(const EvaluationAggregate& r, std::initializer_list<const char*> stages) {
  double sum = 0.0;
  for (const StageTiming& t : r.mean_timings)
    for (const char* s : stages)
      if (t.stage == s) sum += t.seconds;
  return sum;
}

}  // namespace

std::string RenderAccuracyPlotSvg(const std::vector<EvaluationAggregate>& rows) {
  const double w = 460, h = 360;
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\">\n"
      "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
      2 * w, h);
  if (rows.empty()) return svg + "</svg>\n";
  // The accuracy axis starts at a multiple of 10 below the lowest value, so that differences near
  // 100 % stay visible.
  double lowest = 100.0;
  for (const EvaluationAggregate& r : rows) {
    lowest = std::min({lowest, 100.0 * r.correct_fraction, 100.0 * r.micro_recall});
  }
  const double acc_min = std::max(0.0, std::floor((lowest - 1.0) / 10.0) * 10.0);
  svg += Chart(
      0, 0, w, h, "Accuracy", "% of real tubes / of tube points", acc_min, 100.0, "{:.0f}", rows,
      {{"correct tubes", "#1b7f2a", [](const EvaluationAggregate& r) { return 100.0 * r.correct_fraction; }},
       {"correct + partially correct", "#c26a00",
        [](const EvaluationAggregate& r) {
          return 100.0 * (r.total_correct + r.total_partially_correct) / std::max(1u, r.real_tubes);
        }},
       {"micro-recall (points)", "#4e79a7",
        [](const EvaluationAggregate& r) { return 100.0 * r.micro_recall; }, true}});
  double t_max = 0.0;
  for (const EvaluationAggregate& r : rows) t_max = std::max(t_max, r.mean_total_seconds);
  t_max = std::max(0.01, t_max * 1.15);
  svg += Chart(w, 0, w, h, "Mean modeling time", "seconds", 0.0, t_max, "{:.2f}", rows,
               {{"total", "#111111", [](const EvaluationAggregate& r) { return r.mean_total_seconds; }},
                {"prepare + filter + normals", "#e15759",
                 [](const EvaluationAggregate& r) {
                   return StageMean(r, {"prepare", "filter", "normals"});
                 }},
                {"segmentation", "#59a14f",
                 [](const EvaluationAggregate& r) { return StageMean(r, {"segmentation"}); }, true},
                {"cylinders + joining", "#b07aa1",
                 [](const EvaluationAggregate& r) {
                   return StageMean(r, {"cylinders", "joining"});
                 },
                 true}});
  return svg + "</svg>\n";
}

}  // namespace tubepick::cli
