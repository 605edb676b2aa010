// Top-down SVG pictures of one evaluated scene (hand-written SVG, no dependencies).
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "clients/cli/eval/eval_report.h"
#include "clients/cli/eval/svg_util.h"
#include "core/common/tube_graph.h"

namespace tubepick::cli {
namespace {

// Drawing units are millimetres of the bin frame; one panel shows the bin plus a margin.
constexpr double kMargin = 40.0;          // around the bin, mm
constexpr double kTitle = 56.0;           // title band above each panel
constexpr double kHeader = 84.0;          // scene header above the panels
constexpr double kGap = 24.0;             // between panels
constexpr double kPointSize = 2.6;        // side of a point's square, mm
constexpr std::size_t kMaxPoints = 7000;  // points drawn per panel
constexpr const char* kFont = "font-family=\"DejaVu Sans, Arial, Helvetica, sans-serif\"";

struct Panel {
  double ox = 0.0, oy = 0.0;             // top-left corner of the panel's drawing area (below its title)
  double length = 800.0, width = 600.0;  // bin inner size, mm
  double X(double x_m) const { return ox + kMargin + (x_m * 1000.0 + length / 2.0); }
  double Y(double y_m) const { return oy + kMargin + (width / 2.0 - y_m * 1000.0); }
  double w() const { return length + 2 * kMargin; }
  double h() const { return width + 2 * kMargin; }
};

// Points grouped by colour into one <path> per colour (small files, fast to render).
std::string PointPaths(const Panel& p, const SceneSnapshot& s,
                       const std::vector<std::string>& colour_of_point, double opacity) {
  const std::size_t n = s.points_Bin.size();
  const std::size_t stride = std::max<std::size_t>(1, (n + kMaxPoints - 1) / kMaxPoints);
  std::map<std::string, std::string> paths;
  for (std::size_t i = 0; i < n; i += stride) {
    const auto& q = s.points_Bin[i];
    paths[colour_of_point[i]] += fmt::format("M{:.0f} {:.0f}h{}v{}h-{}z", p.X(q.x()) - kPointSize / 2,
                                             p.Y(q.y()) - kPointSize / 2, kPointSize, kPointSize, kPointSize);
  }
  std::string out;
  // Grey (background / unlabelled) first so colours stay on top.
  auto emit = [&](const std::string& colour, const std::string& d) {
    out += fmt::format("<path fill=\"{}\" fill-opacity=\"{}\" d=\"{}\"/>\n", colour, opacity, d);
  };
  const std::string grey = PaletteColour(-1);
  if (paths.count(grey)) emit(grey, paths[grey]);
  for (const auto& [colour, d] : paths)
    if (colour != grey) emit(colour, d);
  return out;
}

std::string PanelFrame(const Panel& p, const std::string& title, const std::string& subtitle) {
  std::string out;
  out +=
      fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"#fbfbfb\" stroke=\"#bbb\"/>\n",
                  p.ox, p.oy, p.w(), p.h());
  out += fmt::format(
      "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#555\" "
      "stroke-width=\"3\"/>\n",
      p.X(-p.length / 2000.0), p.Y(p.width / 2000.0), p.length, p.width);
  out += fmt::format("<text x=\"{}\" y=\"{}\" {} font-size=\"30\" font-weight=\"bold\">{}</text>\n", p.ox + 4,
                     p.oy - kTitle + 30, kFont, XmlEscape(title));
  out += fmt::format("<text x=\"{}\" y=\"{}\" {} font-size=\"22\" fill=\"#444\">{}</text>\n", p.ox + 4,
                     p.oy - kTitle + 52, kFont, XmlEscape(subtitle));
  return out;
}

// Text with a white halo so it stays legible over points.
std::string Label(double x, double y, const std::string& text, const std::string& colour, int size = 24) {
  return fmt::format(
      "<text x=\"{:.0f}\" y=\"{:.0f}\" {} font-size=\"{}\" font-weight=\"bold\" fill=\"{}\" stroke=\"white\" "
      "stroke-width=\"5\" paint-order=\"stroke\" text-anchor=\"middle\">{}</text>\n",
      x, y, kFont, size, colour, XmlEscape(text));
}

std::string Polyline(const Panel& p, const std::vector<Eigen::Vector3d>& pts, const std::string& style) {
  std::string d;
  for (const auto& q : pts) d += fmt::format("{}{:.1f},{:.1f}", d.empty() ? "" : " ", p.X(q.x()), p.Y(q.y()));
  return fmt::format("<polyline fill=\"none\" points=\"{}\" {}/>\n", d, style);
}

std::string VerdictText(const RealTubeEvaluation& r) {
  switch (r.verdict) {
    case TubeVerdict::kCorrect:
      return "ok";
    case TubeVerdict::kPartiallyCorrect:
      return "part";
    case TubeVerdict::kHidden:
      return "hidden";
    case TubeVerdict::kNotCorrect:
      return r.failure == TubeFailure::kUnderCovered ? "under" : ToString(r.failure);
  }
  return "";
}

std::string VerdictColour(TubeVerdict v) {
  switch (v) {
    case TubeVerdict::kCorrect:
      return "#1b7f2a";
    case TubeVerdict::kPartiallyCorrect:
      return "#c26a00";
    case TubeVerdict::kNotCorrect:
      return "#c00000";
    case TubeVerdict::kHidden:
      return "#777777";
  }
  return "#000";
}

}  // namespace

std::string RenderSceneSvg(const EvaluatedScene& scene) {
  const SceneSnapshot& s = scene.snapshot;
  const SceneEvaluation& e = scene.evaluation;
  Panel base;
  base.length = s.bin.inner_size.x() * 1000.0;
  base.width = s.bin.inner_size.y() * 1000.0;
  const double pw = base.w(), ph = base.h();
  Panel panels[4];
  for (int k = 0; k < 4; ++k) {
    panels[k] = base;
    panels[k].ox = kGap + (k % 2) * (pw + kGap);
    panels[k].oy = kHeader + kTitle + (k / 2) * (ph + kTitle + kGap);
  }
  const double total_w = 2 * pw + 3 * kGap, total_h = kHeader + 2 * (ph + kTitle) + 2 * kGap;
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{:.0f}\" height=\"{:.0f}\" viewBox=\"0 0 {:.0f} "
      "{:.0f}\">\n",
      total_w * 0.6, total_h * 0.6, total_w, total_h);
  svg += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  double time_s = e.total_seconds;
  svg += fmt::format(
      "<text x=\"{}\" y=\"40\" {} font-size=\"34\" font-weight=\"bold\">{}</text>\n", kGap, kFont,
      XmlEscape(fmt::format("Scene {} ({} tube{}{}) - top view, x right, y up", scene.name, scene.tube_count,
                            scene.tube_count == 1 ? "" : "s",
                            scene.scene_seed >= 0 ? fmt::format(", seed {}", scene.scene_seed) : "")));
  svg += fmt::format("<text x=\"{}\" y=\"74\" {} font-size=\"25\">{}</text>\n", kGap, kFont,
                     XmlEscape(fmt::format(
                         "correct {}, partially correct {}, not correct {}, hidden {} | micro-recall {:.3f}, "
                         "precision {:.3f} | {} filtered points, modeling {:.3f} s",
                         e.correct, e.partially_correct, e.not_correct, e.hidden, e.micro_recall(),
                         e.micro_precision(), e.filtered_points, time_s)));

  const std::size_t n = s.points_Bin.size();
  std::vector<std::string> colours(n);

  // 1. Ground truth.
  {
    const Panel& p = panels[0];
    svg += PanelFrame(p, "1. Filtered cloud by ground truth",
                      fmt::format("{} real tubes, line = true axis, label = verdict", scene.tube_count));
    for (std::size_t i = 0; i < n; ++i) colours[i] = PaletteColour(s.truth[i]);
    svg += PointPaths(p, s, colours, 1.0);
    for (const auto& line : s.real_centrelines) {
      if (!line.empty())
        svg += Polyline(p, line, "stroke=\"#222\" stroke-width=\"1.5\" stroke-opacity=\"0.6\"");
    }
    for (std::size_t j = 0; j < e.real_tubes.size(); ++j) {
      // Label at the visible point nearest the centroid of the tube's visible points.
      Eigen::Vector2d sum = Eigen::Vector2d::Zero();
      int count = 0;
      for (std::size_t i = 0; i < n; ++i) {
        if (s.truth[i] != static_cast<int>(j)) continue;
        sum += s.points_Bin[i].head<2>().cast<double>();
        ++count;
      }
      Eigen::Vector2d at;
      if (count > 0) {
        const Eigen::Vector2d centroid = sum / count;
        double best = 1e9;
        for (std::size_t i = 0; i < n; ++i) {
          if (s.truth[i] != static_cast<int>(j)) continue;
          const double d = (s.points_Bin[i].head<2>().cast<double>() - centroid).norm();
          if (d < best) best = d, at = s.points_Bin[i].head<2>().cast<double>();
        }
      } else if (j < s.real_centrelines.size() && !s.real_centrelines[j].empty()) {
        at = s.real_centrelines[j][s.real_centrelines[j].size() / 2].head<2>();
      } else {
        continue;
      }
      const RealTubeEvaluation& r = e.real_tubes[j];
      svg += Label(p.X(at.x()), p.Y(at.y()) + 7, fmt::format("T{} {}", j, VerdictText(r)),
                   VerdictColour(r.verdict), 20);
    }
  }
  // 2. Segments.
  {
    const Panel& p = panels[1];
    svg += PanelFrame(
        p, "2. Segments (region growing)",
        fmt::format("{} segments, {} visible tube sections, grey = none", e.segments, e.visible_sections));
    for (std::size_t i = 0; i < n; ++i) colours[i] = PaletteColour(s.segment[i] < 0 ? -1 : s.segment[i] % 40);
    svg += PointPaths(p, s, colours, 1.0);
  }
  // 3. Cylinders.
  {
    const Panel& p = panels[2];
    std::size_t cylinders = 0;
    for (const Tube& t : s.tubes) cylinders += t.cylinders.size();
    svg += PanelFrame(p, "3. Fitted cylinders",
                      fmt::format("{} cylinders, band = diameter, line = axis", cylinders));
    for (std::size_t i = 0; i < n; ++i) colours[i] = "#d9d9d9";
    svg += PointPaths(p, s, colours, 1.0);
    int k = 0;
    for (const Tube& t : s.tubes) {
      for (const Cylinder& c : t.cylinders) {
        svg += fmt::format(
            "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"{}\" "
            "stroke-opacity=\"0.65\" "
            "stroke-width=\"{:.1f}\"/>\n",
            p.X(c.start.x()), p.Y(c.start.y()), p.X(c.end.x()), p.Y(c.end.y()), PaletteColour(k++ % 40),
            2000.0 * c.radius);
        svg += fmt::format(
            "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#111\" "
            "stroke-width=\"1.5\"/>\n",
            p.X(c.start.x()), p.Y(c.start.y()), p.X(c.end.x()), p.Y(c.end.y()));
      }
    }
  }
  // 4. Virtual tubes, coloured like the real tube they are matched to.
  {
    const Panel& p = panels[3];
    svg += PanelFrame(
        p, "4. Virtual tubes (joined)",
        fmt::format("{} virtual tubes, colour = matched real tube, dashed = joint", s.tubes.size()));
    auto colour_of_virtual = [&](int v) {
      if (v < 0) return PaletteColour(-1);
      const int real = e.virtual_tubes[v].matched_real;
      return PaletteColour(real >= 0 ? real : static_cast<int>(e.real_tubes.size()) + 10 + v);
    };
    for (std::size_t i = 0; i < n; ++i) colours[i] = colour_of_virtual(s.virtual_label[i]);
    svg += PointPaths(p, s, colours, 0.55);
    for (std::size_t v = 0; v < s.tubes.size(); ++v) {
      const auto& cyl = s.tubes[v].cylinders;
      for (const AxisPiece& piece : TubeAxisPieces(s.tubes[v])) {
        // Cylinders solid, joints (and junction links) dashed.
        svg += fmt::format(
            "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#111\" {}/>\n",
            p.X(piece.a.x()), p.Y(piece.a.y()), p.X(piece.b.x()), p.Y(piece.b.y()),
            piece.cylinder >= 0 ? "stroke-width=\"4\" stroke-linecap=\"round\""
                                : "stroke-width=\"2.5\" stroke-dasharray=\"6 5\"");
      }
      if (cyl.empty()) continue;
      const VirtualTubeEvaluation& ve = e.virtual_tubes[v];
      const Cylinder& mid = cyl[cyl.size() / 2];
      const std::string text = ve.matched_real >= 0
                                   ? fmt::format("v{}=T{}{}", v, ve.matched_real, ve.pure ? "" : "!")
                                   : fmt::format("v{}", v);
      svg += Label(p.X(mid.centre().x()), p.Y(mid.centre().y()) - 14, text, ve.pure ? "#111" : "#c00000", 22);
    }
  }
  svg += "</svg>\n";
  return svg;
}

}  // namespace tubepick::cli
