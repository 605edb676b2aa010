#include "clients/cli/eval/svg_util.h"

#include <fmt/core.h>

#include <array>
#include <cmath>

#include "core/modeling/cloud_io.h"

namespace tubepick::cli {

std::string PaletteColour(int i) {
  static constexpr std::array<const char*, 10> kTableau{"#4e79a7", "#f28e2b", "#e15759", "#76b7b2",
                                                        "#59a14f", "#edc948", "#b07aa1", "#ff9da7",
                                                        "#9c755f", "#2f4b7c"};
  if (i < 0) return "#c8c8c8";
  if (i < static_cast<int>(kTableau.size())) return kTableau[i];
  // Past the table: the same distinct golden-angle colours as the PLY stage dumps.
  const Rgb c = LabelColour(i);
  return fmt::format("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]);
}

}  // namespace tubepick::cli
