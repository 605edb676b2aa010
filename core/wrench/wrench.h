#pragma once

#include <Eigen/Core>

namespace tubepick {

/// One force/torque sensor reading.
///
/// Frame: the F/T sensor frame S, whose axes are parallel to the TCP frame's axes (the sensor sits
/// on the tool axis between flange and gripper, so S and Tcp differ only by a translation along
/// that axis). A device driver mounted with another orientation re-expresses its readings first.
/// Because the translation is along the tool axis and, at lift time, the payload's weight acts
/// along the same (vertical) axis, the horizontal torques about the sensor origin equal those
/// about the TCP: the resolution-rotation axis computed from them is valid at the TCP.
///
/// Sign: `force` is the force and `torque` the moment (about the sensor origin) that the payload
/// exerts on the sensor, as the thesis reads them (§5.2.5: "F_z on the z+ axis (pointing
/// upwards)"; holding weight lowers the upward force component).
struct Wrench {
  /// Force, newtons, in S.
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  /// Torque about the sensor origin, newton-metres, in S.
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
};

}  // namespace tubepick
