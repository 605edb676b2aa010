#include "core/common/cell_config.h"

#include <cmath>
#include <utility>

#include "core/common/cell_config_fields.h"
#include "core/common/config_fields.h"
#include "core/common/errors.h"
#include "core/common/require.h"

namespace tubepick {

double MetresPer(LengthUnit unit) { return unit == LengthUnit::kMillimetre ? 0.001 : 1.0; }

LengthUnit ParseLengthUnit(const std::string& text, const std::string& field) {
  if (text == "m") return LengthUnit::kMetre;
  if (text == "mm") return LengthUnit::kMillimetre;
  throw InvalidArgument(field + ": unknown unit '" + text + "' (expected 'm' or 'mm')");
}

std::string ToString(LengthUnit unit) { return unit == LengthUnit::kMillimetre ? "mm" : "m"; }

std::string ToString(TubeTopology topology) {
  switch (topology) {
    case TubeTopology::kLinear:
      return "linear";
    case TubeTopology::kBranched:
      return "branched";
    case TubeTopology::kAuto:
      return "auto";
  }
  return "?";
}

std::string ToString(JunctionShape shape) {
  switch (shape) {
    case JunctionShape::kAny:
      return "any";
    case JunctionShape::kWye:
      return "wye";
    case JunctionShape::kTee:
      return "tee";
  }
  return "?";
}

JunctionShape ParseJunctionShape(const std::string& text, const std::string& field) {
  if (text == "any") return JunctionShape::kAny;
  if (text == "wye") return JunctionShape::kWye;
  if (text == "tee") return JunctionShape::kTee;
  throw InvalidArgument(field + ": unknown junction shape '" + text + "' (expected any, wye or tee)");
}

TubeTopology ParseTubeTopology(const std::string& text, const std::string& field) {
  if (text == "linear") return TubeTopology::kLinear;
  if (text == "branched") return TubeTopology::kBranched;
  if (text == "auto") return TubeTopology::kAuto;
  throw InvalidArgument(field + ": unknown topology '" + text + "' (expected linear, branched or auto)");
}

Eigen::Isometry3d SensorConfig::DefaultX_BinSensor() {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  // Optical frame looking down: rotation of π about x (x right, y down, z forward = −z_bin).
  X.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(0.0, 0.0, 1.1);
  return X;
}

void JunctionLayout::Validate(const std::string& prefix, double tube_length) const {
  if (junctions > kMaxJunctions) {
    throw InvalidArgument(prefix + ".junctions: " + std::to_string(junctions) + " is above " +
                          std::to_string(kMaxJunctions) + " (junctions of one part)");
  }
  for (const auto& [key, value] : {std::pair<const char*, double>{"junction_spacing", junction_spacing},
                                   std::pair<const char*, double>{"branch_length", branch_length}}) {
    const std::string field = prefix + "." + key;
    RequireInRange(value, 0.0, 10.0, field);
    if (tube_length > 0.0 && value >= tube_length) {
      throw InvalidArgument(field + ": " + FormatNumber(value) + " m is not shorter than the tube (" +
                            FormatNumber(tube_length) + " m" +
                            "): a run of a part is part of its length (millimetres given as metres?)");
    }
  }
}

void CellConfig::Validate() const {
  for (int i = 0; i < 3; ++i) {
    RequireInRange(bin.inner_size[i], 0.01, 10.0, "bin.inner_size[" + std::to_string(i) + "]");
  }
  if (!sensor.X_BinSensor.matrix().allFinite()) throw InvalidArgument("sensor.pose_in_bin: non-finite pose");
  if (sensor.X_BinSensor.translation().z() <= 0.0) {
    throw InvalidArgument(
        "sensor.pose_in_bin.position: the sensor must be above the bin floor (z > 0), got z = " +
        std::to_string(sensor.X_BinSensor.translation().z()));
  }
  RequireInRange(tube.radius, 0.001, 0.2, "tube.radius");
  RequireInRange(tube.length, 0.0, 10.0, "tube.length");
  RequireInRange(tube.mass, 0.001, 50.0, "tube.mass");
  tube.layout.Validate("tube", tube.length);
  if (!place.X_BinPlace.matrix().allFinite()) throw InvalidArgument("place.pose_in_bin: non-finite pose");
}

CellConfig ParseCellConfig(const std::string& yaml_text) {
  CellConfig cell;
  ParseFields(yaml_text, "cell config", cell);
  cell.Validate();
  return cell;
}

CellConfig LoadCellConfig(const std::string& path) {
  try {
    return ParseCellConfig(ReadTextFile(path));
  } catch (const InvalidArgument& e) {
    throw InvalidArgument("cell config '" + path + "': " + e.what());
  }
}

std::string DumpCellConfig(const CellConfig& cell) {
  return DumpFields(cell, "One robot cell: bin, scanner pose and the tubes it holds. SI units (m, kg).");
}

}  // namespace tubepick
