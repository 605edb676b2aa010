#pragma once

// The YAML fields of the cell config (ParseCellConfig, DumpCellConfig and the server config's
// `cell` section), declared once for the visitors of core/common/config_fields.h. Private to core
// and the server.

#include "core/common/cell_config.h"

namespace tubepick {

template <typename Visit>
void DescribeFields(Visit& v, BinConfig& bin) {
  v("inner_size", bin.inner_size, "Inner length (x), width (y) and wall height (z), m.");
}

template <typename Visit>
void DescribeFields(Visit& v, SensorConfig& sensor) {
  v.Pose("pose_in_bin", sensor.X_BinSensor,
         "X_BinSensor: the optical frame (x right, y down, z forward) in the bin frame.");
  v.Enum(
      "unit", sensor.unit, [](LengthUnit unit) { return ToString(unit); }, ParseLengthUnit,
      "Unit of the sensor's clouds: m or mm.");
}

template <typename Visit>
void DescribeFields(Visit& v, TubeConfig& tube) {
  v("radius", tube.radius, "Tube radius, m.");
  v("length", tube.length,
    "Curve length, m (joining builds no tube longer than 1.04 times it); 0 = unknown.");
  v("mass", tube.mass, "Mass of one tube, kg.");
  v.Enum(
      "topology", tube.topology, [](TubeTopology t) { return ToString(t); }, ParseTubeTopology,
      "linear, branched (hose assemblies: junctions are looked for) or auto (decided per scene).");
  v.Enum(
      "junction_shape", tube.junction_shape, [](JunctionShape s) { return ToString(s); }, ParseJunctionShape,
      "Branched tubes: any, wye (arms 120 deg apart) or tee (a run and a branch at 90 deg).");
  v("junctions", tube.layout.junctions, "Branched tubes: junctions of one part (its drawing); 0 = unknown.");
  v("junction_spacing", tube.layout.junction_spacing,
    "Branched tubes: run between two adjacent junctions along its axis, m; 0 = unknown.");
  v("branch_length", tube.layout.branch_length,
    "Branched tubes: longest run from a junction to a free end, m; 0 = unknown.");
}

template <typename Visit>
void DescribeFields(Visit& v, PlaceConfig& place) {
  v.Pose("pose_in_bin", place.X_BinPlace,
         "X_BinPlace: the frame a placed tube's PCA frame is aligned with, bin frame.");
}

template <typename Visit>
void DescribeFields(Visit& v, CellConfig& cell) {
  v.Section("bin", cell.bin, "The bin: origin at the centre of its floor, z up, x along its length.");
  v.Section("sensor", cell.sensor);
  v.Section("tube", cell.tube);
  v.Section("place", cell.place);
}

}  // namespace tubepick
