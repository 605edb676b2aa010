#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Geometry>

namespace tubepick {

/// Unit in which a cloud's coordinates arrive.
enum class LengthUnit { kMetre, kMillimetre };

/// Scale factor from `unit` to metres.
double MetresPer(LengthUnit unit);
/// "m" or "mm". @throws InvalidArgument for anything else, naming `field`.
LengthUnit ParseLengthUnit(const std::string& text, const std::string& field);
std::string ToString(LengthUnit unit);

/// The bin: origin at the centre of its floor, z up, x along its length.
struct BinConfig {
  /// Inner length (x), width (y) and wall height (z), metres.
  Eigen::Vector3d inner_size{0.80, 0.60, 0.20};
};

struct SensorConfig {
  /// X_BinSensor: pose of the sensor's optical frame (x right, y down, z forward) in the bin frame.
  Eigen::Isometry3d X_BinSensor = DefaultX_BinSensor();
  /// Unit of the clouds this sensor produces.
  LengthUnit unit = LengthUnit::kMetre;

  /// 1.1 m above the floor centre, looking straight down (optical z = -bin z).
  static Eigen::Isometry3d DefaultX_BinSensor();
};

/// What shape of tube a cell holds.
enum class TubeTopology {
  /// Paths only: modeling looks for no junctions.
  kLinear,
  /// Trees (hose assemblies with T- and Y-pieces): chains are joined at junctions.
  kBranched,
  /// Decided per scene: junctions are kept when the scene shows enough of them
  /// (modeling.junctions.auto_min_junctions and auto_min_share).
  kAuto,
};

/// "linear", "branched", "auto".
std::string ToString(TubeTopology topology);
/// @throws InvalidArgument naming `field`, the value and the accepted ones.
TubeTopology ParseTubeTopology(const std::string& text, const std::string& field);

/// The fitting at the junctions of branched tubes, as the cell knows it: modeling accepts a
/// junction only when the angles between its three arms fit the shape
/// (modeling.junctions.shape_tolerance).
enum class JunctionShape {
  /// No expectation (mixed fittings, wire harnesses): any angles, up to
  /// modeling.junctions.max_branches_per_node arms.
  kAny,
  /// Y-pieces: three arms 120° apart.
  kWye,
  /// T-pieces: a straight run and a branch at 90° to it (arms 90°, 90°, 180° apart).
  kTee,
};

/// "any", "wye", "tee".
std::string ToString(JunctionShape shape);
/// @throws InvalidArgument naming `field`, the value and the accepted ones.
JunctionShape ParseJunctionShape(const std::string& text, const std::string& field);

/// Branched tubes: what the part's drawing says of its junctions; 0 = not known. Junction
/// joining refuses a tree the drawing rules out (JunctionParams::layout_tolerance): two junctions
/// joined by a run of another length than junction_spacing, or more junctions than the part has,
/// counting one hidden past each junction's arm that ends longer than branch_length. Set C: 2
/// junctions 0.30 m apart (the trunk), branches of 0.10–0.15 m.
struct JunctionLayout {
  /// Junctions of one part.
  std::uint32_t junctions = 0;
  /// Length of the run between two adjacent junctions, along its axis, metres.
  double junction_spacing = 0.0;
  /// Longest run from a junction to a free end, metres.
  double branch_length = 0.0;

  /// Most junctions a part may be said to have.
  static constexpr std::uint32_t kMaxJunctions = 64;

  /// Whether any of it is known.
  bool known() const { return junctions > 0 || junction_spacing > 0.0 || branch_length > 0.0; }
  /// @throws InvalidArgument naming "<prefix>.<key>" and the value; runs must be shorter than a
  /// known `tube_length` (0 = unknown).
  void Validate(const std::string& prefix, double tube_length) const;
};

struct TubeConfig {
  /// Tube radius, metres.
  double radius = 0.0125;
  /// Expected curve length, metres (a branched tube: all its branches together); 0 = unknown.
  /// Joining builds no tube or tree longer than a share of it (modeling.joining and
  /// modeling.junctions max_length_share, 1.04 in the fast profile).
  double length = 0.50;
  /// Mass of one tube, kg.
  double mass = 0.055;
  /// Linear tubes, branched ones, or decided per scene.
  TubeTopology topology = TubeTopology::kLinear;
  /// Branched tubes: the fitting at their junctions.
  JunctionShape junction_shape = JunctionShape::kAny;
  /// Branched tubes: where their junctions are (fields junctions, junction_spacing, branch_length).
  JunctionLayout layout;
};

/// Where placed tubes go: X_BinPlace is the destination frame the tube's PCA frame is aligned
/// with, expressed in the bin frame.
struct PlaceConfig {
  Eigen::Isometry3d X_BinPlace = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.8, 0.1));
};

/// One robot cell (ARCHITECTURE.md, "Cell description").
struct CellConfig {
  BinConfig bin;
  SensorConfig sensor;
  TubeConfig tube;
  PlaceConfig place;

  /// @throws InvalidArgument naming the field when a value is non-finite or out of range.
  void Validate() const;
};

/// Loads a cell YAML. Unknown keys are errors.
/// @throws InvalidArgument with the key path and the reason.
CellConfig LoadCellConfig(const std::string& path);
CellConfig ParseCellConfig(const std::string& yaml_text);

/// YAML of every field of `cell`, with comments, that ParseCellConfig reads back to the same cell
/// (poses go through a quaternion, so they return equal to ~1e-15).
std::string DumpCellConfig(const CellConfig& cell);

}  // namespace tubepick
