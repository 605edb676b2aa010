#include "core/wrench/resolution_hold.h"

#include <algorithm>
#include <string>

#include "core/common/errors.h"
#include "core/common/require.h"

namespace tubepick {

ResolutionHold PlanResolutionHold(const Wrench& reference, const Wrench& lifted,
                                  const Eigen::Isometry3d& X_BinTcpLift,
                                  const Eigen::Vector3d& bin_inner_size, double wall_margin) {
  RequireFiniteVector(reference.force, "reference.force");
  RequireFiniteVector(reference.torque, "reference.torque");
  RequireFiniteVector(lifted.force, "lifted.force");
  RequireFiniteVector(lifted.torque, "lifted.torque");
  RequireRigid(X_BinTcpLift, "X_BinTcpLift");
  RequireNonNegative(wall_margin, "resolution_wall_margin");
  const Eigen::Matrix3d R_BinTcp = X_BinTcpLift.linear();
  const Eigen::Vector3d force_Bin = R_BinTcp * (lifted.force - reference.force);
  const Eigen::Vector3d torque_Bin = R_BinTcp * (lifted.torque - reference.torque);
  ResolutionHold hold;
  const double weight = -force_Bin.z();
  if (weight > 0.0) hold.p_TcpPayload_Bin = Eigen::Vector3d(torque_Bin.y(), -torque_Bin.x(), 0.0) / weight;
  const Eigen::Vector3d tcp = X_BinTcpLift.translation();
  Eigen::Vector3d target = -hold.p_TcpPayload_Bin;
  for (int axis = 0; axis < 2; ++axis) {
    const double reach = std::max(0.0, 0.5 * bin_inner_size[axis] - wall_margin);
    target[axis] = std::clamp(target[axis], -reach, reach);
  }
  hold.shift_Bin = Eigen::Vector3d(target.x() - tcp.x(), target.y() - tcp.y(), 0.0);
  return hold;
}

}  // namespace tubepick
