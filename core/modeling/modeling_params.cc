#include "core/modeling/modeling_params.h"

#include <cmath>
#include <string>

#include "core/common/errors.h"
#include "core/common/require.h"

namespace tubepick {

void ModelingParams::Validate() const {
  for (std::size_t i = 0; i < filters.size(); ++i) {
    ValidateFilter(filters[i], "modeling.filters[" + std::to_string(i) + "]." + FilterName(filters[i]));
  }
  RequirePositive(normals.radius, "modeling.normals.radius");

  const SegmentationParams& s = segmentation;
  if (s.neighbours == 0) throw InvalidArgument("modeling.segmentation.neighbours: must be > 0, got 0");
  if (s.min_cluster_size > s.max_cluster_size) {
    throw InvalidArgument("modeling.segmentation.min_cluster_size: " + std::to_string(s.min_cluster_size) +
                          " exceeds max_cluster_size " + std::to_string(s.max_cluster_size));
  }
  RequireInRange(s.smoothness_threshold, 1e-6, M_PI, "modeling.segmentation.smoothness_threshold");
  RequireNonNegative(s.curvature_threshold, "modeling.segmentation.curvature_threshold");
  RequirePositive(s.residual_threshold, "modeling.segmentation.residual_threshold");

  const CylinderFitParams& c = cylinders;
  if (c.min_inliers < 3) {
    throw InvalidArgument("modeling.cylinders.min_inliers: must be >= 3, got " +
                          std::to_string(c.min_inliers));
  }
  RequirePositive(c.min_radius, "modeling.cylinders.min_radius");
  RequirePositive(c.max_radius, "modeling.cylinders.max_radius");
  if (c.min_radius > c.max_radius) {
    throw InvalidArgument("modeling.cylinders.min_radius: " + std::to_string(c.min_radius) +
                          " exceeds max_radius " + std::to_string(c.max_radius));
  }
  RequirePositive(c.distance_threshold, "modeling.cylinders.distance_threshold");
  RequireInRange(c.normal_distance_weight, 0.0, 1.0, "modeling.cylinders.normal_distance_weight");
  if (c.max_iterations == 0) throw InvalidArgument("modeling.cylinders.max_iterations: must be > 0, got 0");
  RequireInRange(c.probability, 1e-6, 1.0 - 1e-9, "modeling.cylinders.probability");
  RequireNonNegative(c.safety_length, "modeling.cylinders.safety_length");
  RequireNonNegative(c.safety_radius, "modeling.cylinders.safety_radius");

  const JoiningParams& j = joining;
  RequireNonNegative(j.max_distance, "modeling.joining.max_distance");
  RequireInRange(j.max_angle, 0.0, 2.0 * M_PI, "modeling.joining.max_angle");
  RequireNonNegative(j.angular_weight, "modeling.joining.angular_weight");
  RequireNonNegative(j.max_tube_length, "modeling.joining.max_tube_length");
  RequireNonNegative(j.max_length_share, "modeling.joining.max_length_share");
  RequireNonNegative(j.radius_shortcut, "modeling.joining.radius_shortcut");
  RequirePositive(j.visibility_pixel_angle, "modeling.joining.visibility_pixel_angle");
  RequireNonNegative(j.visibility_min_gap, "modeling.joining.visibility_min_gap");
  if (j.visibility_window > 1000) {
    throw InvalidArgument("modeling.joining.visibility_window: " + std::to_string(j.visibility_window) +
                          " is out of range [0, 1000]");
  }
  junctions.Validate();
  plausibility.Validate();
  if (threads > 1024)
    throw InvalidArgument("modeling.threads: " + std::to_string(threads) + " is out of range [0, 1024]");
}

ModelingParams FastModelingProfile() {
  ModelingParams p;
  CropBoxParams crop;  // the bin interior: removes floor, walls and ground in one pass (§5.2.1)
  // 100 000 points rather than 40 000, with the minimum segment and cylinder at 30 points rather
  // than 60: a tree's 10 cm branch half hidden under another tube kept too few points to make a
  // segment, so its tree came out split (report.json: a tree with 9 % or more of its points in no
  // model was correct 2 times in 10). On 20 bins per point (`tubepick eval --generate N --preset P
  // --per-count 20`, docs/ACCURACY.md): 10 set-C trees 74.0 -> 93.0 % correct, 20 set-A tubes
  // 88.2 -> 99.2 %, 20 set-B tubes 83.0 -> 98.2 %, 10 linear tubes unchanged. The price: the
  // modeling stages about 2.5x slower, a plan through the server about 2x (docs/PERFORMANCE.md,
  // "The point budget"). 150 000 points gained nothing more.
  RandomSampleParams sample;
  sample.count = 100000;
  RadiusOutlierParams radius;
  radius.radius = 0.006;
  radius.min_neighbours = 5;
  p.filters = {crop, sample, radius};

  p.normals.radius = 0.006;
  p.normals.max_neighbours = 40;
  p.normals.search_surface = SearchSurface::kFiltered;

  p.segmentation.min_cluster_size = 30;
  p.segmentation.neighbours = 24;
  p.segmentation.smoothness_threshold = 7.0 * M_PI / 180.0;
  p.segmentation.curvature_threshold = 0.2;

  p.cylinders.min_inliers = 30;
  p.cylinders.min_radius = 0.007;
  p.cylinders.max_radius = 0.018;
  p.cylinders.distance_threshold = 0.004;
  // With a 4 mm threshold, 0.1 made the normal term dominate (inliers needed a normal within
  // ~2° of radial; k = 40 normals have a median error of ~2°), so curved sections lost most of
  // their inliers. 0.03 tolerates ~7° (tubepick eval: 94.0 % → 98.3 % correct, docs/ACCURACY.md).
  p.cylinders.normal_distance_weight = 0.03;
  p.cylinders.max_iterations = 300;
  p.cylinders.probability = 0.99;
  p.cylinders.safety_length = 0.01;
  // Wider than the thesis' 2 cm: at a gentle bend one cylinder can span two sections, and the
  // far-side surface points then lie up to r + axis offset ≈ 2.5 cm from its axis; left behind
  // they form an overlapping cylinder that derails joining.
  p.cylinders.safety_radius = 0.03;
  p.cylinders.refine = true;

  // Global joining: same cost (< 1 ms), slightly more correct tubes than greedy on 200 simulated
  // bins (98.6 % vs 98.3 %, 10 tubes: 9.65 vs 9.55 correct; docs/ACCURACY.md).
  p.joining.strategy = JoiningStrategy::kGlobal;
  // 100° of α + β rather than Table 4.3's 90°: a 45° bend (set B) hidden under another tube
  // kinks the two visible ends by more than 90° once each end cylinder's fit tilts a little. On
  // 200 bins of 1–10 tubes per set, set B 91.7 → 96.8 % correct (seed 500: 92.3 → 97.1 %), set A
  // unchanged (98.6 %); 20 set-A tubes 74.2 → 73.8 %. 110° took set A's 20-tube bins to 73.5 %
  // (docs/ACCURACY.md).
  p.joining.max_angle = 100.0 * M_PI / 180.0;
  // Gaps up to 18 cm rather than Table 4.3's 10 cm: a tube that dives under two or three others,
  // or under one along its length, leaves a hidden gap of 10–16 cm (9 of the 11 set-B 10-tube
  // failures at 10 cm). The visibility test still refuses a gap the scanner saw through, and no
  // joined tube grows past 1.04 times the cell's tube length (a longer one holds a stranger's
  // piece, as in every merge left at 18 cm). 20 bins per point (docs/ACCURACY.md): set B 10 tubes
  // 9.45 → 9.90 correct, 20 tubes 72.5 → 83.0 %, set A 20 tubes 73.8 → 88.2 %.
  p.joining.max_distance = 0.18;
  p.joining.max_length_share = 1.04;
  return p;
}

ModelingParams ThesisModelingProfile() {
  ModelingParams p;
  // Table 4.2, with the bin crop box of §5.2.1 in place of the depth pass-through. The floor is
  // kept (min_z below it) so that, as in chapter 4, the RANSAC plane filter removes it.
  CropBoxParams crop;
  crop.min_z = -0.02;
  RandomSampleParams sample1;
  sample1.count = 100000;
  RadiusOutlierParams radius1;
  radius1.radius = 0.007;
  radius1.min_neighbours = 10;
  PlaneRemovalParams plane;
  plane.distance_threshold = 0.015;
  plane.probability = 0.2;
  plane.normal_distance_weight = 0.07;
  plane.axis = Eigen::Vector3d::UnitZ();
  plane.max_iterations = 1000;
  plane.eps_angle = 0.14;
  RandomSampleParams sample2;
  sample2.count = 25000;
  RadiusOutlierParams radius2;
  radius2.radius = 0.007;
  radius2.min_neighbours = 15;
  StatisticalOutlierParams sor;
  sor.neighbours = 100;
  sor.stddev_mult = 3.0;
  p.filters = {crop, sample1, radius1, plane, sample2, radius2, sor};

  p.normals.radius = 0.005;
  p.normals.max_neighbours = 0;
  p.normals.search_surface = SearchSurface::kRaw;

  // Table 4.3.
  p.segmentation.min_cluster_size = 100;
  p.segmentation.neighbours = 77;
  p.segmentation.curvature_threshold = 0.2;
  p.segmentation.residual_threshold = 10.0;
  p.segmentation.smoothness_threshold = 5.0 * M_PI / 180.0;

  p.cylinders.min_inliers = 100;
  p.cylinders.min_radius = 0.007;
  p.cylinders.max_radius = 0.015;
  p.cylinders.distance_threshold = 0.02;
  p.cylinders.normal_distance_weight = 0.07;
  p.cylinders.max_iterations = 1000;
  p.cylinders.safety_length = 0.01;
  p.cylinders.safety_radius = 0.02;

  p.joining.max_distance = 0.10;
  p.joining.max_angle = M_PI / 2.0;
  p.joining.angular_weight = 0.001 * 180.0 / M_PI;
  p.joining.max_tube_length = 0.60;
  p.joining.strategy = JoiningStrategy::kGreedy;
  return p;
}

}  // namespace tubepick
