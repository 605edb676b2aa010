#include "core/evaluation/assignment.h"

#include <cmath>
#include <limits>
#include <string>

#include "core/common/errors.h"

namespace tubepick {
namespace {

// Hungarian method for n ≤ m (rows ≤ columns), 1-based potentials as in the classic
// shortest-augmenting-path formulation. Returns the column of each row.
std::vector<std::int32_t> SolveRowsNotMoreThanColumns(const std::vector<std::vector<double>>& a,
                                                      std::size_t n, std::size_t m) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0);
  std::vector<std::size_t> p(m + 1, 0), way(m + 1, 0);  // p[j]: row (1-based) matched to column j
  for (std::size_t i = 1; i <= n; ++i) {
    p[0] = i;
    std::size_t j0 = 0;
    std::vector<double> minv(m + 1, kInf);
    std::vector<char> used(m + 1, 0);
    do {
      used[j0] = 1;
      const std::size_t i0 = p[j0];
      double delta = kInf;
      std::size_t j1 = 0;
      for (std::size_t j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double cur = a[i0 - 1][j - 1] - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {  // strict: the lowest column index wins ties (deterministic)
          delta = minv[j];
          j1 = j;
        }
      }
      for (std::size_t j = 0; j <= m; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {
      const std::size_t j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<std::int32_t> column_of_row(n, -1);
  for (std::size_t j = 1; j <= m; ++j) {
    if (p[j] != 0) column_of_row[p[j] - 1] = static_cast<std::int32_t>(j - 1);
  }
  return column_of_row;
}

}  // namespace

Assignment SolveMinCostAssignment(const std::vector<std::vector<double>>& cost) {
  const std::size_t rows = cost.size();
  const std::size_t columns = rows == 0 ? 0 : cost.front().size();
  for (std::size_t r = 0; r < rows; ++r) {
    if (cost[r].size() != columns) {
      throw InvalidArgument("assignment: row " + std::to_string(r) + " has " +
                            std::to_string(cost[r].size()) + " costs, row 0 has " + std::to_string(columns));
    }
    for (std::size_t c = 0; c < columns; ++c) {
      if (!std::isfinite(cost[r][c])) {
        throw InvalidArgument("assignment: cost[" + std::to_string(r) + "][" + std::to_string(c) +
                              "] is not finite");
      }
    }
  }
  Assignment out;
  out.column_of_row.assign(rows, -1);
  out.row_of_column.assign(columns, -1);
  if (rows == 0 || columns == 0) return out;

  if (rows <= columns) {
    out.column_of_row = SolveRowsNotMoreThanColumns(cost, rows, columns);
  } else {
    std::vector<std::vector<double>> transposed(columns, std::vector<double>(rows));
    for (std::size_t r = 0; r < rows; ++r)
      for (std::size_t c = 0; c < columns; ++c) transposed[c][r] = cost[r][c];
    const std::vector<std::int32_t> row_of_column = SolveRowsNotMoreThanColumns(transposed, columns, rows);
    for (std::size_t c = 0; c < columns; ++c)
      out.column_of_row[row_of_column[c]] = static_cast<std::int32_t>(c);
  }
  for (std::size_t r = 0; r < rows; ++r) {
    const std::int32_t c = out.column_of_row[r];
    if (c < 0) continue;
    out.row_of_column[c] = static_cast<std::int32_t>(r);
    out.total_cost += cost[r][c];
  }
  return out;
}

Assignment MatchMaxOverlap(const std::vector<std::vector<std::uint64_t>>& overlap, std::size_t columns) {
  std::vector<std::vector<double>> cost(overlap.size());
  for (std::size_t r = 0; r < overlap.size(); ++r) {
    if (overlap[r].size() != columns) {
      throw InvalidArgument("assignment: row " + std::to_string(r) + " has " +
                            std::to_string(overlap[r].size()) + " overlaps, expected " +
                            std::to_string(columns));
    }
    cost[r].reserve(overlap[r].size());
    for (std::uint64_t v : overlap[r]) cost[r].push_back(-static_cast<double>(v));
  }
  Assignment a = SolveMinCostAssignment(cost);
  a.row_of_column.assign(columns, -1);
  a.total_cost = 0.0;
  for (std::size_t r = 0; r < overlap.size(); ++r) {
    const std::int32_t c = a.column_of_row[r];
    if (c < 0) continue;
    if (overlap[r][c] == 0) {
      a.column_of_row[r] = -1;
    } else {
      a.row_of_column[c] = static_cast<std::int32_t>(r);
      a.total_cost -= static_cast<double>(overlap[r][c]);
    }
  }
  return a;
}

}  // namespace tubepick
