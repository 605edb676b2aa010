#pragma once

#include <cstdint>
#include <vector>

namespace tubepick {

/// Result of a rectangular linear assignment.
struct Assignment {
  /// Per row: the column assigned to it, or −1 when the row is left out (more rows than columns).
  std::vector<std::int32_t> column_of_row;
  /// Per column: the row assigned to it, or −1.
  std::vector<std::int32_t> row_of_column;
  /// Sum of cost[r][column_of_row[r]] over the assigned rows.
  double total_cost = 0.0;
};

/// Minimum-cost assignment (Hungarian method, Kuhn–Munkres with potentials, O(n²·m)) on a
/// rectangular `cost` matrix of rows × columns (columns = the length of the first row, so a
/// matrix without rows has no columns either): exactly min(rows, columns) pairs, each row and
/// each column used at most once, minimising the summed cost. Deterministic: among optimal
/// answers the same one is always returned.
/// @throws InvalidArgument when the rows have different lengths or a cost is not finite.
Assignment SolveMinCostAssignment(const std::vector<std::vector<double>>& cost);

/// Maximum-overlap matching used by the evaluation (thesis §4.5.2): rows and columns of the
/// rows × `columns` matrix `overlap` are paired to maximise the summed overlap; pairs whose
/// overlap is 0 are dropped (left as −1), so a row is matched only to a column it shares
/// something with. `columns` is explicit because `overlap` may have no rows. `total_cost` is
/// minus the summed overlap of the kept pairs.
/// @throws InvalidArgument when a row does not have `columns` entries.
Assignment MatchMaxOverlap(const std::vector<std::vector<std::uint64_t>>& overlap, std::size_t columns);

}  // namespace tubepick
