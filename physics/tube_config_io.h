#pragma once

#include <string>
#include <vector>

#include "physics/tube_geometry.h"

namespace tubepick::physics {

/// The published `tube_configurations` text format (Leão et al. 2022 dataset; see
/// /work/shared/data/sim-eval/README.md, "Format notes"), whitespace separated:
///
///     <number of tubes>
///     <tube id> <n_nodes> <n_edges>                          once per tube, followed by
///     <node id> x y z radius                                 n_nodes node lines and
///     <name> <node1> <node2> <order> <radius> cx cy cz qw qx qy qz <length>   n_edges edge lines
///
/// Positions in metres, Bin frame. The edge quaternion is stored (w, x, y, z): checked against
/// all 549 edges of the 20 sample bins, reading it that way maps the cylinder's local +z onto
/// (node2 − node1)/|node2 − node1| (cosine ≥ 0.999998 for every edge), while reading it as
/// (x, y, z, w) does not. Note that ARCHITECTURE.md's quaternions (proto, YAML) are (x, y, z, w):
/// only this file format is scalar-first. Reading keeps the stored values (the quaternion is
/// normalised); nothing is recomputed from the nodes.

/// Parses the text. `source` names the input in error messages (a path, "<string>").
/// @throws InvalidArgument "<source>:<line>: <reason>" for a malformed or truncated file, bad
///         counts, a non-numeric or non-finite field, duplicate node ids, an edge referring to an
///         unknown node, a zero quaternion, or trailing content.
std::vector<TubeGeometry> ParseTubeConfigurations(const std::string& text,
                                                  const std::string& source = "<string>");

/// Reads a file. @throws InvalidArgument as ParseTubeConfigurations, or when it cannot be opened.
std::vector<TubeGeometry> ReadTubeConfigurations(const std::string& path);

/// The text for `tubes`, with up to 9 significant digits (sub-micrometre at bin scale), nodes and
/// edges in their stored order.
std::string FormatTubeConfigurations(const std::vector<TubeGeometry>& tubes);

/// Writes FormatTubeConfigurations to `path`. @throws InvalidArgument when it cannot be written.
void WriteTubeConfigurations(const std::string& path, const std::vector<TubeGeometry>& tubes);

}  // namespace tubepick::physics
