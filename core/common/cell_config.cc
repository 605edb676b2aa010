#include "core/common/cell_config.h"

#include <cmath>

#include "core/common/errors.h"
#include "core/common/require.h"
#include "core/common/yaml_reader.h"

namespace tubepick {
namespace {

Eigen::Isometry3d ReadPose(YamlMap& parent, const std::string& key, const Eigen::Isometry3d& fallback) {
  YamlMap map(parent.Child(key), parent.PathOf(key));
  Eigen::Vector3d position = fallback.translation();
  const Eigen::Quaterniond q0(fallback.linear());
  Eigen::Vector4d xyzw(q0.x(), q0.y(), q0.z(), q0.w());
  map.Read("position", position);
  if (map.Has("orientation_xyzw")) {
    YAML::Node n = map.Child("orientation_xyzw");
    if (!n.IsSequence() || n.size() != 4) {
      throw InvalidArgument(map.PathOf("orientation_xyzw") + ": expected a list of 4 numbers (x, y, z, w)");
    }
    for (int i = 0; i < 4; ++i) {
      try {
        xyzw[i] = n[i].as<double>();
      } catch (const YAML::Exception&) {
        throw InvalidArgument(map.PathOf("orientation_xyzw") + ": expected numbers");
      }
      RequireFinite(xyzw[i], map.PathOf("orientation_xyzw"));
    }
  }
  map.RejectUnknown();
  const double norm = xyzw.norm();
  if (std::abs(norm - 1.0) > 1e-3) {
    throw InvalidArgument(map.PathOf("orientation_xyzw") +
                          ": quaternion must be unit length, |q| = " + std::to_string(norm));
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::Quaterniond(xyzw[3], xyzw[0], xyzw[1], xyzw[2]).normalized().toRotationMatrix();
  pose.translation() = position;
  return pose;
}

}  // namespace

double MetresPer(LengthUnit unit) { return unit == LengthUnit::kMillimetre ? 0.001 : 1.0; }

LengthUnit ParseLengthUnit(const std::string& text, const std::string& field) {
  if (text == "m") return LengthUnit::kMetre;
  if (text == "mm") return LengthUnit::kMillimetre;
  throw InvalidArgument(field + ": unknown unit '" + text + "' (expected 'm' or 'mm')");
}

std::string ToString(LengthUnit unit) { return unit == LengthUnit::kMillimetre ? "mm" : "m"; }

Eigen::Isometry3d SensorConfig::DefaultX_BinSensor() {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  // Optical frame looking down: rotation of π about x (x right, y down, z forward = −z_bin).
  X.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(0.0, 0.0, 1.1);
  return X;
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
  if (!place.X_BinPlace.matrix().allFinite()) throw InvalidArgument("place.pose_in_bin: non-finite pose");
}

CellConfig ParseCellConfig(const std::string& yaml_text) {
  const YAML::Node root = ParseYaml(yaml_text, "cell config");
  YamlMap top(root, "");
  CellConfig cell;
  {
    YamlMap bin(top.Child("bin"), "bin");
    bin.Read("inner_size", cell.bin.inner_size);
    bin.RejectUnknown();
  }
  {
    YamlMap sensor(top.Child("sensor"), "sensor");
    cell.sensor.X_BinSensor = ReadPose(sensor, "pose_in_bin", cell.sensor.X_BinSensor);
    std::string unit = ToString(cell.sensor.unit);
    sensor.Read("unit", unit);
    cell.sensor.unit = ParseLengthUnit(unit, "sensor.unit");
    sensor.RejectUnknown();
  }
  {
    YamlMap tube(top.Child("tube"), "tube");
    tube.Read("radius", cell.tube.radius);
    tube.Read("length", cell.tube.length);
    tube.Read("mass", cell.tube.mass);
    tube.RejectUnknown();
  }
  {
    YamlMap place(top.Child("place"), "place");
    cell.place.X_BinPlace = ReadPose(place, "pose_in_bin", cell.place.X_BinPlace);
    place.RejectUnknown();
  }
  top.RejectUnknown();
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

}  // namespace tubepick
