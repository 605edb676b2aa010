#include "physics/random_tubes.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "core/common/errors.h"
#include "core/common/segment_geometry.h"

namespace tubepick::physics {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kDeg = M_PI / 180.0;

std::string BranchName(std::size_t index) { return "branches[" + std::to_string(index) + "]"; }

/// Lengths as a count of resolution steps; `what` names the field in errors.
long Steps(double value, double resolution, const std::string& what) {
  const double steps = value / resolution;
  const long rounded = std::lround(steps);
  if (std::abs(steps - static_cast<double>(rounded)) > 1e-6) {
    throw InvalidArgument(what + " = " + std::to_string(value) +
                          " is not a multiple of length_resolution = " + std::to_string(resolution));
  }
  return rounded;
}

/// Algorithm 2 lines 3–10: number of cylinders and their lengths, metres.
std::vector<double> DrawLengths(const TubeBranchSpec& spec, const RandomTubeParams& params,
                                std::mt19937_64& rng) {
  const int c = std::uniform_int_distribution<int>(spec.min_cylinders, spec.max_cylinders)(rng);
  std::vector<double> lengths;
  if (params.length_resolution > 0.0) {
    const double res = params.length_resolution;
    const long cl_min = Steps(params.min_cylinder_length, res, "min_cylinder_length");
    long remaining = Steps(spec.length, res, "length");
    for (int i = 0; i <= c - 2; ++i) {
      const long length = std::uniform_int_distribution<long>(cl_min, remaining - (c - 1 - i) * cl_min)(rng);
      lengths.push_back(static_cast<double>(length) * res);
      remaining -= length;
    }
    lengths.push_back(static_cast<double>(remaining) * res);
  } else {
    const double cl_min = params.min_cylinder_length;
    double remaining = spec.length;
    for (int i = 0; i <= c - 2; ++i) {
      const double length =
          std::uniform_real_distribution<double>(cl_min, remaining - (c - 1 - i) * cl_min)(rng);
      lengths.push_back(length);
      remaining -= length;
    }
    lengths.push_back(remaining);
  }
  return lengths;
}

Eigen::Vector3d Spherical(double theta, double phi) {
  return Eigen::Vector3d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
}

/// Algorithm 2 lines 11–25 for one chain: the c + 1 endpoints starting at `start`. The first
/// direction is `first_direction` when given (non-root branches), else drawn as in lines 14–17.
std::vector<Eigen::Vector3d> DrawChain(const TubeBranchSpec& spec, const std::vector<double>& lengths,
                                       const Eigen::Vector3d& start, const Eigen::Vector3d* first_direction,
                                       std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Vector3d> endpoints{start};
  Eigen::Vector3d previous_direction = Eigen::Vector3d::UnitZ();
  for (std::size_t i = 0; i < lengths.size(); ++i) {
    Eigen::Vector3d direction;
    if (i == 0 && first_direction != nullptr) {
      direction = *first_direction;
    } else {
      const double phi = 2.0 * M_PI * unit(rng);
      if (i == 0) {
        direction = Spherical(M_PI * unit(rng), phi);
      } else {
        const double theta = spec.min_angle + (spec.max_angle - spec.min_angle) * unit(rng);
        direction = RotationFromZ(previous_direction) * Spherical(theta, phi);
      }
    }
    direction.normalize();
    endpoints.push_back(endpoints.back() + lengths[i] * direction);
    previous_direction = direction;
  }
  return endpoints;
}

/// One draw of the whole tube (all branches), centred on its bounding box.
TubeGeometry DrawTube(const RandomTubeParams& params, int id, std::mt19937_64& rng) {
  int max_graph_id = 0;
  for (const TubeBranchSpec& b : params.branches)
    max_graph_id = std::max({max_graph_id, b.from_node, b.to_node});
  int next_joint_id = max_graph_id + 2;

  TubeGeometry tube;
  tube.id = id;
  std::map<int, Eigen::Vector3d> away_tangent;  // graph node → unit tangent pointing away from it
  std::map<int, double> base_azimuth;           // split node → random azimuth
  std::uniform_real_distribution<double> unit(0.0, 1.0);

  for (std::size_t k = 0; k < params.branches.size(); ++k) {
    const TubeBranchSpec& spec = params.branches[k];
    const std::vector<double> lengths = DrawLengths(spec, params, rng);
    Eigen::Vector3d start = Eigen::Vector3d::Zero();
    Eigen::Vector3d first_direction;
    const Eigen::Vector3d* first = nullptr;
    if (k == 0) {
      tube.nodes.push_back({spec.from_node, start, params.radius});
    } else {
      start = tube.Node(spec.from_node).centre;
      const Eigen::Vector3d& ref = away_tangent.at(spec.from_node);
      if (spec.split_random) {
        std::normal_distribution<double> normal(0.0, 1.0);
        do {
          first_direction = Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
        } while (!(first_direction.norm() > 1e-9));
        first_direction.normalize();
      } else {
        if (!base_azimuth.contains(spec.from_node)) base_azimuth[spec.from_node] = 2.0 * M_PI * unit(rng);
        const double azimuth = base_azimuth[spec.from_node] + spec.split_azimuth;
        const Eigen::Vector3d perpendicular = Eigen::AngleAxisd(azimuth, ref) * ref.unitOrthogonal();
        first_direction = std::cos(spec.split_angle) * ref + std::sin(spec.split_angle) * perpendicular;
      }
      first = &first_direction;
    }
    const std::vector<Eigen::Vector3d> points = DrawChain(spec, lengths, start, first, rng);

    std::vector<int> ids{spec.from_node};
    for (std::size_t i = 1; i + 1 < points.size(); ++i) {
      ids.push_back(next_joint_id);
      tube.nodes.push_back({next_joint_id++, points[i], params.radius});
    }
    ids.push_back(spec.to_node);
    tube.nodes.push_back({spec.to_node, points.back(), params.radius});
    for (std::size_t i = 0; i + 1 < ids.size(); ++i) {
      TubeEdge edge;
      edge.name = "e_" + std::to_string(ids[i]) + "_" + std::to_string(ids[i + 1]);
      edge.node1 = ids[i];
      edge.node2 = ids[i + 1];
      edge.order = static_cast<int>(i) + 1;
      edge.radius = params.radius;
      tube.edges.push_back(edge);
    }
    if (!away_tangent.contains(spec.from_node))
      away_tangent[spec.from_node] = (points[1] - points[0]).normalized();
    if (!away_tangent.contains(spec.to_node)) {
      away_tangent[spec.to_node] = (points[points.size() - 2] - points.back()).normalized();
    }
  }

  Eigen::Vector3d lo = tube.nodes.front().centre, hi = lo;
  for (const TubeNode& n : tube.nodes) {
    lo = lo.cwiseMin(n.centre);
    hi = hi.cwiseMax(n.centre);
  }
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  for (TubeNode& n : tube.nodes) n.centre -= centre;
  for (TubeEdge& e : tube.edges) SetEdgeFromNodes(tube, e);
  return tube;
}

}  // namespace

RandomTubeParams RandomTubeParams::SetA() { return RandomTubeParams{}; }

RandomTubeParams RandomTubeParams::SetB() {
  RandomTubeParams params;
  params.branches.front().max_angle = 45.0 * kDeg;
  return params;
}

RandomTubeParams RandomTubeParams::SetC() {
  RandomTubeParams params = SetCY();
  for (std::size_t k = 1; k < params.branches.size(); ++k) params.branches[k].split_random = true;
  return params;
}

RandomTubeParams RandomTubeParams::SetCY() {
  RandomTubeParams params;
  auto branch = [](int from, int to, double length, int c_min, int c_max, double azimuth) {
    TubeBranchSpec b;
    b.from_node = from;
    b.to_node = to;
    b.length = length;
    b.min_cylinders = c_min;
    b.max_cylinders = c_max;
    b.min_angle = 0.0;
    b.max_angle = 20.0 * kDeg;
    b.split_angle = 120.0 * kDeg;
    b.split_azimuth = azimuth;
    return b;
  };
  params.branches = {branch(1, 2, 0.30, 5, 10, 0.0), branch(1, 3, 0.10, 2, 5, 0.0),
                     branch(1, 4, 0.10, 2, 5, M_PI), branch(2, 5, 0.10, 2, 5, 0.0),
                     branch(2, 6, 0.15, 2, 6, M_PI)};
  return params;
}

RandomTubeParams RandomTubeParams::Preset(const std::string& name) {
  if (name == "A") return SetA();
  if (name == "B") return SetB();
  if (name == "C") return SetC();
  if (name == "CY") return SetCY();
  throw InvalidArgument("unknown random tube preset '" + name + "' (expected A, B, C or CY)");
}

void RandomTubeParams::Validate() const {
  auto fail = [](const std::string& field, double value, const std::string& why) {
    throw InvalidArgument("random tubes: " + field + " = " + std::to_string(value) + ": " + why);
  };
  if (!(radius > 0.0 && radius < 1.0)) fail("radius", radius, "expected 0 < R < 1 m");
  if (!(min_cylinder_length > 0.0 && std::isfinite(min_cylinder_length))) {
    fail("min_cylinder_length", min_cylinder_length, "expected > 0");
  }
  if (!(length_resolution >= 0.0 && std::isfinite(length_resolution))) {
    fail("length_resolution", length_resolution, "expected ≥ 0");
  }
  if (max_attempts < 1) fail("max_attempts", max_attempts, "expected ≥ 1");
  if (branches.empty()) throw InvalidArgument("random tubes: branches is empty");
  std::set<int> nodes{branches.front().from_node};
  for (std::size_t k = 0; k < branches.size(); ++k) {
    const TubeBranchSpec& b = branches[k];
    const std::string name = BranchName(k);
    if (b.from_node < 1) fail(name + ".from_node", b.from_node, "node ids start at 1");
    if (b.to_node < 1) fail(name + ".to_node", b.to_node, "node ids start at 1");
    if (!nodes.contains(b.from_node))
      fail(name + ".from_node", b.from_node, "not created by an earlier branch");
    if (nodes.contains(b.to_node)) fail(name + ".to_node", b.to_node, "already used (tubes are trees)");
    nodes.insert(b.to_node);
    if (!(b.length > 0.0 && std::isfinite(b.length))) fail(name + ".length", b.length, "expected > 0");
    if (b.min_cylinders < 1) fail(name + ".min_cylinders", b.min_cylinders, "expected ≥ 1");
    if (b.max_cylinders < b.min_cylinders)
      fail(name + ".max_cylinders", b.max_cylinders, "below min_cylinders");
    if (b.max_cylinders * min_cylinder_length > b.length + 1e-12) {
      fail(name + ".max_cylinders", b.max_cylinders,
           "max_cylinders · min_cylinder_length exceeds the branch length " + std::to_string(b.length));
    }
    if (!(b.min_angle >= 0.0 && b.min_angle <= b.max_angle && b.max_angle <= M_PI)) {
      fail(name + ".min_angle", b.min_angle, "expected 0 ≤ min_angle ≤ max_angle ≤ π");
    }
    if (!std::isfinite(b.split_angle) || !std::isfinite(b.split_azimuth)) {
      fail(name + ".split_angle", b.split_angle, "expected finite split angles");
    }
    if (length_resolution > 0.0) {
      Steps(b.length, length_resolution, name + ".length");
      Steps(min_cylinder_length, length_resolution, "min_cylinder_length");
    }
  }
}

double SelfClearance(const TubeGeometry& tube) {
  const std::size_t n = tube.nodes.size();
  // Along-tube distances between nodes (Floyd–Warshall; tubes have a few dozen nodes).
  std::vector<double> dist(n * n, kInf);
  for (std::size_t i = 0; i < n; ++i) dist[i * n + i] = 0.0;
  std::vector<std::pair<int, int>> ends;
  for (const TubeEdge& e : tube.edges) {
    const int a = tube.FindNode(e.node1), b = tube.FindNode(e.node2);
    const double length = (tube.nodes[a].centre - tube.nodes[b].centre).norm();
    dist[a * n + b] = std::min(dist[a * n + b], length);
    dist[b * n + a] = std::min(dist[b * n + a], length);
    ends.emplace_back(a, b);
  }
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < n; ++j)
        dist[i * n + j] = std::min(dist[i * n + j], dist[i * n + k] + dist[k * n + j]);
    }
  }
  double clearance = kInf;
  for (std::size_t e = 0; e < tube.edges.size(); ++e) {
    for (std::size_t f = e + 1; f < tube.edges.size(); ++f) {
      const double two_r = tube.edges[e].radius + tube.edges[f].radius;
      const auto [a, b] = ends[e];
      const auto [c, d] = ends[f];
      const double gap = std::min({dist[a * n + c], dist[a * n + d], dist[b * n + c], dist[b * n + d]});
      if (gap <= two_r) continue;  // neighbours along the tube: they may legitimately come close
      const double distance = ClosestPointsOfSegments(tube.nodes[a].centre, tube.nodes[b].centre,
                                                      tube.nodes[c].centre, tube.nodes[d].centre)
                                  .distance;
      clearance = std::min(clearance, distance - two_r);
    }
  }
  return clearance;
}

TubeGeometry GenerateRandomTube(const RandomTubeParams& params, int id, std::mt19937_64& rng) {
  params.Validate();
  for (int attempt = 0; attempt < params.max_attempts; ++attempt) {
    TubeGeometry tube = DrawTube(params, id, rng);
    if (!params.reject_self_intersection || SelfClearance(tube) >= 0.0) return tube;
  }
  throw InvalidArgument("random tubes: no tube without self-intersection in max_attempts = " +
                        std::to_string(params.max_attempts) + " draws; loosen the angles or the radius");
}

std::vector<TubeGeometry> GenerateRandomTubes(int count, const RandomTubeParams& params, std::uint64_t seed) {
  if (count < 0) throw InvalidArgument("random tubes: count = " + std::to_string(count) + " must be ≥ 0");
  std::mt19937_64 rng(seed);
  std::vector<TubeGeometry> tubes;
  tubes.reserve(count);
  for (int i = 0; i < count; ++i) tubes.push_back(GenerateRandomTube(params, i + 1, rng));
  return tubes;
}

}  // namespace tubepick::physics
