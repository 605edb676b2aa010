#include "core/params.h"

#include "core/common/config_fields.h"
#include "core/common/errors.h"
#include "core/params_fields.h"

namespace tubepick {
namespace internal {

const char* AxisName(Axis axis) { return axis == Axis::kX ? "x" : axis == Axis::kY ? "y" : "z"; }

Axis ParseAxis(const std::string& text, const std::string& key) {
  if (text == "x") return Axis::kX;
  if (text == "y") return Axis::kY;
  if (text == "z") return Axis::kZ;
  throw InvalidArgument(key + ": unknown axis '" + text + "' (expected x, y or z)");
}

const char* FrameName(FilterFrame frame) { return frame == FilterFrame::kBin ? "bin" : "sensor"; }

FilterFrame ParseFrame(const std::string& text, const std::string& key) {
  if (text == "bin") return FilterFrame::kBin;
  if (text == "sensor") return FilterFrame::kSensor;
  throw InvalidArgument(key + ": unknown frame '" + text + "' (expected bin or sensor)");
}

const char* SurfaceName(SearchSurface surface) { return surface == SearchSurface::kRaw ? "raw" : "filtered"; }

SearchSurface ParseSurface(const std::string& text, const std::string& key) {
  if (text == "raw") return SearchSurface::kRaw;
  if (text == "filtered") return SearchSurface::kFiltered;
  throw InvalidArgument(key + ": unknown search surface '" + text + "' (expected raw or filtered)");
}

const char* StrategyName(JoiningStrategy strategy) {
  return strategy == JoiningStrategy::kGreedy ? "greedy" : "global";
}

JoiningStrategy ParseStrategy(const std::string& text, const std::string& key) {
  if (text == "greedy") return JoiningStrategy::kGreedy;
  if (text == "global") return JoiningStrategy::kGlobal;
  throw InvalidArgument(key + ": unknown strategy '" + text + "' (expected greedy or global)");
}

namespace {

FilterStep DefaultFilter(const std::string& name, const std::string& key) {
  if (name == "crop_box") return CropBoxParams{};
  if (name == "pass_through") return PassThroughParams{};
  if (name == "voxel_grid") return VoxelGridParams{};
  if (name == "random_sample") return RandomSampleParams{};
  if (name == "radius_outlier") return RadiusOutlierParams{};
  if (name == "statistical_outlier") return StatisticalOutlierParams{};
  if (name == "plane_removal") return PlaneRemovalParams{};
  throw InvalidArgument(key + ": unknown filter '" + name +
                        "' (expected crop_box, pass_through, voxel_grid, random_sample, radius_outlier, "
                        "statistical_outlier or plane_removal)");
}

}  // namespace

const VariantListSpec<FilterStep>& FilterListSpec() {
  static const VariantListSpec<FilterStep> spec{"filters", "- random_sample: {count: 40000}", FilterName,
                                                DefaultFilter};
  return spec;
}

}  // namespace internal

void Params::Validate() const {
  modeling.Validate();
  planning.Validate();
  wrench.Validate();
  placement.Validate();
  // A lift from a tilted grasp is analysed at the grasp's tilt: AnalyzeWrench would refuse it.
  if (planning.grasps.max_tilt > wrench.max_tilt) {
    throw InvalidArgument("planning.grasps.max_tilt: " + std::to_string(planning.grasps.max_tilt) +
                          " rad exceeds wrench.max_tilt " + std::to_string(wrench.max_tilt) +
                          " rad: AnalyzeWrench would refuse the lifts of the most tilted grasps");
  }
}

std::vector<std::string> ProfileNames() { return {"fast", "thesis"}; }

Params ProfileParams(const std::string& name) {
  Params p;
  if (name == "fast") {
    p.modeling = FastModelingProfile();
    // The thesis' 45° left rubber hoses hanging (§5.3.4: friction too high; tan 45° = 1 is the
    // rubber's μ); 55° frees more and stays within the arm's 60° tilt. On the same 33 double picks
    // of generated set-C pvc bins, carried over the bin's middle first, 55° freed 19 and 45° 13
    // (`tubepick resolution-trials`, docs/ACCURACY.md).
    p.wrench.rotation_angle = 55.0 * M_PI / 180.0;
    // And when several still hang, 55° about the horizontal perpendicular to the torque axis: on
    // those 33 double picks 23 freed against 19 with no tree outside the bin, and in six 20-tree
    // set-C cell rounds 6 of 9 resolutions freed one tree against 6 of 11 (docs/ACCURACY.md).
    p.wrench.variant = ResolutionVariant::kTorqueAxisThenPerpendicular;
    // Algorithm 3's F_tol (0.25 N) is 0.46 of a 55 g PVC tube's weight and 0.31 of a set-C tree's:
    // a tree with a third of another hanging from it read as one (1.30 tubes) and both were carried
    // out. Single lifts in the simulated cell weighed 0.91-1.07 tubes (2187 lifts), several 1.38 and
    // more (docs/ACCURACY.md): the band is at most a fifth of a tube's weight either side.
    p.wrench.force_tolerance_share = 0.2;
  } else if (name == "thesis") {
    p.modeling = ThesisModelingProfile();
  } else {
    throw InvalidArgument("profile: unknown profile '" + name + "' (expected fast or thesis)");
  }
  return p;
}

Params ParseParams(const std::string& yaml_text, const Params& base) {
  Params p = base;
  ParseFields(yaml_text, "params", p);
  p.Validate();
  return p;
}

Params LoadParams(const std::string& path, const Params& base) {
  try {
    return ParseParams(ReadTextFile(path), base);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument("params '" + path + "': " + e.what());
  }
}

std::string DumpParams(const Params& params) { return DumpFields(params); }

}  // namespace tubepick
