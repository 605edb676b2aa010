#include "core/evaluation/visible_sections.h"

#include <cmath>
#include <numeric>
#include <string>
#include <unordered_map>

#include "core/common/errors.h"
#include "core/common/grid_cell_key.h"

namespace tubepick {
namespace {

struct DisjointSets {
  std::vector<std::uint32_t> parent;
  explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t Find(std::uint32_t x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  }
  void Unite(std::uint32_t a, std::uint32_t b) {
    a = Find(a);
    b = Find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace

std::vector<std::uint32_t> CountVisibleSections(const Points& points, const std::vector<std::int32_t>& truth,
                                                std::uint32_t tube_count,
                                                const VisibleSectionParams& params) {
  if (truth.size() != points.size()) {
    throw InvalidArgument("visible sections: " + std::to_string(truth.size()) + " labels for " +
                          std::to_string(points.size()) + " points");
  }
  if (!(params.link_radius > 0.0) || !std::isfinite(params.link_radius)) {
    throw InvalidArgument("visible sections: link_radius must be > 0, got " +
                          std::to_string(params.link_radius));
  }
  const double cell = params.link_radius;
  const double r2 = params.link_radius * params.link_radius;
  auto cell_of = [&](const Eigen::Vector3f& p) {
    return Eigen::Vector3i(static_cast<int>(std::floor(p.x() / cell)),
                           static_cast<int>(std::floor(p.y() / cell)),
                           static_cast<int>(std::floor(p.z() / cell)));
  };
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> grid;
  for (std::uint32_t i = 0; i < points.size(); ++i) {
    if (truth[i] < 0 || truth[i] >= static_cast<std::int32_t>(tube_count) || !points[i].allFinite()) continue;
    const Eigen::Vector3i c = cell_of(points[i]);
    grid[GridCellKey(c.x(), c.y(), c.z())].push_back(i);
  }
  DisjointSets sets(points.size());
  for (const auto& [key, members] : grid) {
    for (std::uint32_t i : members) {
      const Eigen::Vector3i c = cell_of(points[i]);
      for (int dx = -1; dx <= 1; ++dx) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dz = -1; dz <= 1; ++dz) {
            const auto it = grid.find(GridCellKey(c.x() + dx, c.y() + dy, c.z() + dz));
            if (it == grid.end()) continue;
            for (std::uint32_t j : it->second) {
              if (j <= i || truth[j] != truth[i]) continue;
              if ((points[i] - points[j]).squaredNorm() <= r2) sets.Unite(i, j);
            }
          }
        }
      }
    }
  }
  std::unordered_map<std::uint32_t, std::uint32_t> component_size;
  for (const auto& [key, members] : grid)
    for (std::uint32_t i : members) ++component_size[sets.Find(i)];
  std::vector<std::uint32_t> sections(tube_count, 0);
  for (const auto& [root, size] : component_size) {
    if (size >= params.min_points) ++sections[truth[root]];
  }
  return sections;
}

}  // namespace tubepick
