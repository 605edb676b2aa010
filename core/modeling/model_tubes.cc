#include "core/modeling/model_tubes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <tuple>
#include <utility>

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include "core/common/errors.h"
#include "core/common/thread_budget.h"
#include "core/modeling/cloud_io.h"
#include "core/modeling/cloud_prepare.h"
#include "core/modeling/cylinder_fit.h"
#include "core/modeling/range_image.h"
#include "core/modeling/tube_joining.h"

namespace tubepick {
namespace {

using Clock = std::chrono::steady_clock;

// Which tube took each of the n filtered points: the tube holding each fitted cylinder, whole
// (joining may reverse it: same segment, same axis) or cut at a junction (its pieces lie on its
// axis).
std::vector<std::int32_t> TubeOfPoint(const std::vector<Tube>& tubes, const std::vector<Cylinder>& fitted,
                                      const std::vector<const std::vector<std::uint32_t>*>& inliers_of,
                                      std::size_t n) {
  std::vector<std::int32_t> tube_of_point(n, -1);
  for (std::size_t k = 0; k < fitted.size(); ++k) {
    const Cylinder& f = fitted[k];
    const Eigen::Vector3d axis = f.axis();
    auto on_axis = [&](const Cylinder& c) {
      const Eigen::Vector3d d = c.centre() - f.start;
      return c.segment_id == f.segment_id && c.radius == f.radius && (d - d.dot(axis) * axis).norm() < 1e-9;
    };
    for (const Tube& tube : tubes) {
      if (std::none_of(tube.cylinders.begin(), tube.cylinders.end(), on_axis)) continue;
      for (const std::uint32_t i : *inliers_of[k]) tube_of_point[i] = static_cast<std::int32_t>(tube.id);
      break;
    }
  }
  return tube_of_point;
}

// The points no fitted cylinder took as an inlier.
Points UnfittedPoints(const Points& points,
                      const std::vector<const std::vector<std::uint32_t>*>& inliers_of) {
  std::vector<char> fitted(points.size(), 0);
  for (const auto* inliers : inliers_of) {
    for (const std::uint32_t i : *inliers) fitted[i] = 1;
  }
  Points out;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!fitted[i]) out.push_back(points[i]);
  }
  return out;
}

// The tubes of JoinModeledTubes, and how they were joined.
struct JoinedTubes {
  std::vector<Tube> tubes;
  /// The whole tubes' length when the cell's tube.length is shorter than the scan shows.
  std::optional<double> scan_length;
  /// Joined as trees (junction joining), not as linear tubes: then the chains it joined and its
  /// decisions.
  bool trees = false;
  std::vector<Tube> chains;
  std::vector<JoinDecision> decisions;
};

// The cylinders joined into tubes: linear (JoinTubesOfLength) or, for a branched or `auto` cell,
// chains joined within stricter limits first (JunctionParams::chain_max_distance), then into trees
// with the rooms past their free ends (from the points no cylinder took); `auto` keeps the plain
// linear joining when the scene does not look branched.
JoinedTubes JoinModeledTubes(const ModelingInput& input, const ModelingParams& params,
                             const std::vector<Cylinder>& cylinders, const Points& filtered,
                             const std::vector<const std::vector<std::uint32_t>*>& inliers_of,
                             const RangeImage* seen, const StopToken* stop) {
  JoinedTubes out;
  if (input.topology != TubeTopology::kLinear) {
    JoiningParams chain_joining = params.joining;
    chain_joining.max_distance = std::min(chain_joining.max_distance, params.junctions.chain_max_distance);
    chain_joining.max_angle = std::min(chain_joining.max_angle, params.junctions.chain_max_angle);
    std::vector<Tube> chains = JoinTubes(cylinders, chain_joining, seen, stop);
    const EndRooms rooms =
        MeasureEndRooms(UnfittedPoints(filtered, inliers_of), chains, params.junctions.end_room, seen);
    JunctionJoining joined = JoinJunctionsOfLength(chains, params.junctions, input.junction_shape, stop,
                                                   rooms, input.tube_length, &out.scan_length, input.layout);
    out.trees = input.topology == TubeTopology::kBranched || LooksBranched(joined, params.junctions);
    spdlog::debug(
        "junctions: {} ({} Y-pieces, {} completions) joining {} of {} chains into {} tubes; topology {}: {}",
        joined.junctions, joined.y_pieces, joined.completions, joined.chains_in_junctions, chains.size(),
        joined.tubes.size(), ToString(input.topology), out.trees ? "branched" : "linear");
    if (out.trees) {
      out.tubes = std::move(joined.tubes);
      out.chains = std::move(chains);
      out.decisions = std::move(joined.decisions);
      return out;
    }
  }
  out.tubes = JoinTubesOfLength(cylinders, params.joining, input.tube_length, seen, stop, &out.scan_length);
  return out;
}

// The cell's tube radius must be one the cylinder fit can find: outside its radii every tube would
// be fitted at a bound (or not at all), a plausible-looking but wrong model.
void RequireRadiusWithinFit(double tube_radius, const CylinderFitParams& cylinders) {
  if (tube_radius <= 0.0) return;  // unknown
  if (tube_radius < cylinders.min_radius || tube_radius > cylinders.max_radius) {
    throw InvalidArgument(fmt::format(
        "tube.radius: {:.4f} m lies outside the radii the modeling fits, [{:.4f}, {:.4f}] m "
        "(modeling.cylinders.min_radius, max_radius): every tube would be fitted wrong; is tube.radius "
        "the radius (not the diameter), in metres? Otherwise widen the fit's radii",
        tube_radius, cylinders.min_radius, cylinders.max_radius));
  }
}

// The fitted cylinders' median radius differs from the cell's tube.radius by more than a fifth
// (fits of the right radius fall within a few per cent of it: docs/ACCURACY.md): a warning.
std::optional<ModelingWarning> TubeRadiusWarning(double tube_radius, const std::vector<Cylinder>& cylinders) {
  constexpr double kTolerance = 0.2;
  if (tube_radius <= 0.0 || cylinders.empty()) return std::nullopt;
  std::vector<double> radii;
  for (const Cylinder& c : cylinders) radii.push_back(c.radius);
  const auto mid = radii.begin() + static_cast<std::ptrdiff_t>(radii.size() / 2);
  std::nth_element(radii.begin(), mid, radii.end());
  const double fitted = *mid;
  if (std::abs(fitted - tube_radius) <= kTolerance * tube_radius) return std::nullopt;
  ModelingWarning w;
  w.code = "tube_radius_differs_from_scan";
  w.stated = tube_radius;
  w.observed = fitted;
  w.message = fmt::format(
      "tube.radius {:.4f} m: the {} cylinders fitted to this scan have a median radius of {:.4f} m, {:.0f} % "
      "{}; is tube.radius the parts' outer radius? Grasp widths, escape distances and simulation use "
      "tube.radius",
      tube_radius, cylinders.size(), fitted, 100.0 * std::abs(fitted / tube_radius - 1.0),
      fitted > tube_radius ? "more" : "less");
  spdlog::warn("{}", w.message);
  return w;
}

// The cell's tube.length is shorter than the tubes the scan shows whole (`scan_length`, their
// median length; `trees`: joined as trees): joined within the scan's length instead, and said, with
// the likely cause.
ModelingWarning TubeLengthWarning(const ModelingInput& input, const ModelingParams& params,
                                  double scan_length, bool trees) {
  const double share = trees ? params.junctions.max_length_share : params.joining.max_length_share;
  ModelingWarning w;
  w.code = "tube_length_shorter_than_scan";
  w.stated = input.tube_length;
  w.observed = scan_length;
  w.message = fmt::format(
      "tube.length {:.3f} m: the {}tubes this scan shows about whole are {:.3f} m long (median), more than "
      "{:.2f} times it; is tube.length {}? Joined as if it were {:.3f} m",
      input.tube_length, trees ? "branched " : "", scan_length, share,
      trees ? "all branches of a part together" : "the parts' whole curve length", scan_length);
  spdlog::warn("{}", w.message);
  return w;
}

double SecondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// SplitMix64: derives independent, reproducible seeds for each stochastic step.
std::uint64_t MixSeed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ULL * (stream + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

template <typename T>
std::vector<T> Subset(const std::vector<T>& values, const std::vector<std::uint32_t>& keep) {
  std::vector<T> out;
  out.reserve(keep.size());
  for (std::uint32_t i : keep) out.push_back(values[i]);
  return out;
}

// The working cloud of the filter pipeline: points, and normals once estimated.
struct WorkingCloud {
  OrientedPoints cloud;
  std::vector<std::uint32_t> source_index;  // index in the input cloud
  bool has_normals = false;

  void Keep(const std::vector<std::uint32_t>& keep) {
    cloud.points = Subset(cloud.points, keep);
    source_index = Subset(source_index, keep);
    if (has_normals) {
      cloud.normals = Subset(cloud.normals, keep);
      cloud.curvature = Subset(cloud.curvature, keep);
    }
  }
};

// 1. Prepare, in one pass over the input: units, NaN removal, bin frame, the cloud-vs-cell
// evidence and a leading crop box (the rest of the filter chain then sees only the crop). Returns
// the working cloud and the index of the first filter still to apply.
std::pair<WorkingCloud, std::size_t> PrepareStage(const ModelingInput& input, const ModelingParams& params,
                                                  const StopToken* stop, ModelingResult& result) {
  const Clock::time_point t0 = Clock::now();
  PrepareSpec spec;
  spec.bin = input.bin;
  spec.plausibility = params.plausibility;
  const bool raw_surface = params.normals.search_surface == SearchSurface::kRaw;
  spec.raw_region_Bin = raw_surface ? RawRegion::All() : input.raw_region_Bin;
  std::size_t first_filter = 0;
  if (!params.filters.empty()) {
    if (const auto* crop = std::get_if<CropBoxParams>(&params.filters.front())) {
      spec.crop_Bin = CropBoxBounds(*crop, input.bin);
      first_filter = 1;
    }
  }
  PreparedCloud prepared = input.points_Sensor != nullptr
                               ? PrepareCloud(*input.points_Sensor, input.unit, input.X_BinSensor, spec, stop)
                               : PrepareCloud(input.xyz_Sensor, input.unit, input.X_BinSensor, spec, stop);
  result.input_points = prepared.input_points;
  result.dropped_non_finite = prepared.dropped_non_finite;
  result.plausibility = prepared.plausibility;
  result.raw_Bin = std::move(prepared.raw_Bin);
  result.raw_region_Bin = spec.raw_region_Bin;
  result.counts.push_back({"input", result.input_points});
  result.counts.push_back({"finite", result.plausibility.points});
  RequirePlausible(result.plausibility, input.bin, input.unit, input.X_BinSensor, params.plausibility);
  WorkingCloud work;
  work.cloud.points = std::move(prepared.working_Bin);
  work.source_index = std::move(prepared.working_source_index);
  if (first_filter == 1) result.counts.push_back({FilterName(params.filters.front()), work.cloud.size()});
  result.timings.push_back({"prepare", SecondsSince(t0)});
  ThrowIfStopped(stop, "prepare");
  return {std::move(work), first_filter};
}

// Normals of the working cloud (searched in the raw cloud or the working cloud itself); points
// without a finite normal or curvature are dropped.
void EstimateWorkingNormals(const ModelingInput& input, const ModelingParams& params, const StopToken* stop,
                            const ModelingResult& result, WorkingCloud& work) {
  const Eigen::Vector3f viewpoint_Bin = input.X_BinSensor.translation().cast<float>();
  const bool raw_surface = params.normals.search_surface == SearchSurface::kRaw;
  const Points& surface = raw_surface ? result.raw_Bin : work.cloud.points;
  OrientedPoints oriented =
      EstimateNormals(work.cloud.points, surface, params.normals, viewpoint_Bin, stop, params.threads);
  std::vector<std::uint32_t> valid;
  valid.reserve(oriented.size());
  for (std::uint32_t i = 0; i < oriented.size(); ++i) {
    if (oriented.normals[i].allFinite() && std::isfinite(oriented.curvature[i])) valid.push_back(i);
  }
  work.cloud = std::move(oriented);  // same points, same order: source_index still holds
  work.has_normals = true;
  if (valid.size() != work.cloud.size()) work.Keep(valid);
}

// 2. The rest of the filters, with normals estimated when first needed (or after the last filter);
// the filtered cloud goes into the result.
void FilterStage(const ModelingInput& input, const ModelingParams& params, const StopToken* stop,
                 WorkingCloud work, std::size_t first_filter, ModelingResult& result) {
  const FilterContext context{input.X_BinSensor, input.bin};
  double filter_seconds = 0.0, normal_seconds = 0.0;
  auto estimate_normals = [&]() {
    const Clock::time_point tn = Clock::now();
    EstimateWorkingNormals(input, params, stop, result, work);
    result.counts.push_back({"normals", work.cloud.size()});
    normal_seconds += SecondsSince(tn);
  };
  for (std::size_t i = first_filter; i < params.filters.size(); ++i) {
    const FilterStep& step = params.filters[i];
    if (FilterNeedsNormals(step) && !work.has_normals) estimate_normals();
    const Clock::time_point tf = Clock::now();
    const auto keep = ApplyFilter(step, work.cloud.points, work.has_normals ? &work.cloud.normals : nullptr,
                                  context, MixSeed(input.seed, i), stop);
    work.Keep(keep);
    result.counts.push_back({FilterName(step), work.cloud.size()});
    filter_seconds += SecondsSince(tf);
  }
  if (!work.has_normals) estimate_normals();
  result.timings.push_back({"filter", filter_seconds});
  result.timings.push_back({"normals", normal_seconds});
  result.filtered = std::move(work.cloud);
  result.filtered_source_index = std::move(work.source_index);
  for (const auto& p : result.filtered.points)
    result.max_height = std::max(result.max_height, static_cast<double>(p.z()));
  ThrowIfStopped(stop, "filter");
}

// 3. Region-growing segmentation of the filtered cloud.
std::vector<Segment> SegmentationStage(const ModelingParams& params, const StopToken* stop,
                                       ModelingResult& result) {
  const Clock::time_point t0 = Clock::now();
  const OrientedPoints& cloud = result.filtered;
  std::vector<Segment> segments = SegmentRegions(cloud, params.segmentation, stop, params.threads);
  result.segment_count = static_cast<std::uint32_t>(segments.size());
  result.segment_of_point.assign(cloud.size(), -1);
  std::uint64_t segmented = 0;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    for (std::uint32_t i : segments[s]) result.segment_of_point[i] = static_cast<std::int32_t>(s);
    segmented += segments[s].size();
  }
  result.counts.push_back({"segmented", segmented});
  result.timings.push_back({"segmentation", SecondsSince(t0)});
  return segments;
}

// The fitted cylinders of all segments, in segment order, each with its inliers.
struct FittedCylinders {
  std::vector<std::vector<FittedCylinder>> per_segment;
  std::vector<Cylinder> cylinders;
  std::vector<const std::vector<std::uint32_t>*> inliers_of;  // into per_segment
};

// 4. Cylinders per segment, in parallel; per-segment seeds make the result thread-count free.
void CylinderStage(const ModelingInput& input, const ModelingParams& params, const StopToken* stop,
                   const std::vector<Segment>& segments, ModelingResult& result, FittedCylinders& out) {
  const Clock::time_point t0 = Clock::now();
  const OrientedPoints& cloud = result.filtered;
  out.per_segment.assign(segments.size(), {});
  std::exception_ptr failure;
  const int n_segments = static_cast<int>(segments.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(ResolveThreads(params.threads))
  for (int s = 0; s < n_segments; ++s) {
    try {
      out.per_segment[s] = FitCylinders(cloud, segments[s], static_cast<std::uint32_t>(s), params.cylinders,
                                        MixSeed(input.seed, 1000 + static_cast<std::uint64_t>(s)), stop);
    } catch (...) {
#pragma omp critical
      if (!failure) failure = std::current_exception();
    }
  }
  if (failure) std::rethrow_exception(failure);
  std::uint64_t fitted = 0;
  for (const auto& fits : out.per_segment) {
    for (const FittedCylinder& f : fits) {
      out.cylinders.push_back(f.cylinder);
      out.inliers_of.push_back(&f.inliers);
      fitted += f.inliers.size();
    }
  }
  result.cylinder_count = static_cast<std::uint32_t>(out.cylinders.size());
  if (auto warning = TubeRadiusWarning(input.tube_radius, out.cylinders)) result.warnings.push_back(*warning);
  result.counts.push_back({"cylinder_inliers", fitted});
  result.timings.push_back({"cylinders", SecondsSince(t0)});
  ThrowIfStopped(stop, "cylinders");
}

// 5. Tube joining, with the visibility range image of the filtered cloud; 6. junctions.
void JoiningStage(const ModelingInput& input, const ModelingParams& params, const StopToken* stop,
                  const FittedCylinders& fitted, ModelingResult& result) {
  const Clock::time_point t0 = Clock::now();
  const OrientedPoints& cloud = result.filtered;
  std::optional<RangeImage> visibility;
  if (params.joining.visibility_check && !cloud.points.empty()) {
    visibility.emplace(cloud.points, input.X_BinSensor, params.joining.visibility_pixel_angle);
  }
  JoinedTubes joined = JoinModeledTubes(input, params, fitted.cylinders, cloud.points, fitted.inliers_of,
                                        visibility ? &*visibility : nullptr, stop);
  result.tubes = std::move(joined.tubes);
  result.chains = std::move(joined.chains);
  result.join_decisions = std::move(joined.decisions);
  if (joined.scan_length)
    result.warnings.push_back(TubeLengthWarning(input, params, *joined.scan_length, joined.trees));
  result.tube_of_point = TubeOfPoint(result.tubes, fitted.cylinders, fitted.inliers_of, cloud.size());
  result.timings.push_back({"joining", SecondsSince(t0)});
}

}  // namespace

ModelingResult ModelTubes(const ModelingInput& input, const ModelingParams& params, const StopToken* stop) {
  if (input.points_Sensor != nullptr && !input.xyz_Sensor.bytes.empty()) {
    throw std::invalid_argument("ModelingInput: both points_Sensor and xyz_Sensor are set");
  }
  if (input.xyz_Sensor.bytes.size() % 12 != 0) {
    throw InvalidArgument("cloud: " + std::to_string(input.xyz_Sensor.bytes.size()) +
                          " bytes is not a multiple of 12 (packed float32 x, y, z per point)");
  }
  params.Validate();
  RequireRadiusWithinFit(input.tube_radius, params.cylinders);
  const Clock::time_point t_start = Clock::now();
  ModelingResult result;
  auto [work, first_filter] = PrepareStage(input, params, stop, result);
  FilterStage(input, params, stop, std::move(work), first_filter, result);
  const std::vector<Segment> segments = SegmentationStage(params, stop, result);
  FittedCylinders fitted;
  CylinderStage(input, params, stop, segments, result, fitted);
  JoiningStage(input, params, stop, fitted, result);
  result.total_seconds = SecondsSince(t_start);
  spdlog::debug("modeled {} tubes from {} points ({} filtered, {} segments, {} cylinders) in {:.3f} s",
                result.tubes.size(), result.input_points, result.filtered.size(), result.segment_count,
                result.cylinder_count, result.total_seconds);
  return result;
}

ModelingInput ModelingInputFor(const CellConfig& cell) {
  ModelingInput input;
  input.X_BinSensor = cell.sensor.X_BinSensor;
  input.bin = cell.bin;
  input.topology = cell.tube.topology;
  input.junction_shape = cell.tube.junction_shape;
  input.tube_length = cell.tube.length;
  input.layout = cell.tube.layout;
  input.tube_radius = cell.tube.radius;
  return input;
}

void DumpStages(const ModelingResult& result, const std::string& directory) {
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec) throw InvalidArgument("dump-stages: cannot create '" + directory + "': " + ec.message());
  const std::filesystem::path dir(directory);
  const Points& points = result.filtered.points;
  WritePly((dir / "1_filtered.ply").string(), points);

  std::vector<Rgb> colours(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) colours[i] = LabelColour(result.segment_of_point[i]);
  WritePly((dir / "2_segments.ply").string(), points, &colours);

  Points tube_points;
  std::vector<Rgb> tube_colours;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (result.tube_of_point[i] < 0) continue;
    tube_points.push_back(points[i]);
    tube_colours.push_back(LabelColour(result.tube_of_point[i]));
  }
  WritePly((dir / "3_tubes.ply").string(), tube_points, &tube_colours);
}

}  // namespace tubepick
