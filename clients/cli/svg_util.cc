#include "clients/cli/svg_util.h"

#include <fmt/core.h>

#include <array>
#include <cmath>

namespace tubepick::cli {

std::string PaletteColour(int i) {
  static constexpr std::array<const char*, 10> kTableau{"#4e79a7", "#f28e2b", "#e15759", "#76b7b2",
                                                        "#59a14f", "#edc948", "#b07aa1", "#ff9da7",
                                                        "#9c755f", "#2f4b7c"};
  if (i < 0) return "#c8c8c8";
  if (i < static_cast<int>(kTableau.size())) return kTableau[i];
  // HSV with golden-angle hues, medium saturation and value.
  const double h = std::fmod(0.61803398875 * i, 1.0) * 6.0, s = 0.65, v = 0.85;
  const int sector = static_cast<int>(h);
  const double f = h - sector, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  double r = v, g = t, b = p;
  switch (sector % 6) {
    case 1:
      r = q, g = v, b = p;
      break;
    case 2:
      r = p, g = v, b = t;
      break;
    case 3:
      r = p, g = q, b = v;
      break;
    case 4:
      r = t, g = p, b = v;
      break;
    case 5:
      r = v, g = p, b = q;
      break;
    default:
      break;
  }
  return fmt::format("#{:02x}{:02x}{:02x}", static_cast<int>(r * 255), static_cast<int>(g * 255),
                     static_cast<int>(b * 255));
}

std::string XmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace tubepick::cli
