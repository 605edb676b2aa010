#include "core/wrench/resolution_hold.h"

#include <algorithm>
#include <string>

#include "core/common/errors.h"
#include "core/common/require.h"

namespace tubepick {

ResolutionHold PlanResolutionHold(const Wrench& reference, const Wrench& lifted,
                                  const Eigen::Isometry3d& X_BinTcpLift,
                                  const Eigen::Vector3d& bin_inner_size, double wall_margin) {
  RequireRigid(X_BinTcpLift, "X_BinTcpLift");
  RequireNonNegative(wall_margin, "resolution_wall_margin");
  ResolutionHold hold;
  hold.p_TcpPayload_Bin = PayloadOnTool(reference, lifted, X_BinTcpLift.linear()).p_TcpPayload_Bin;
  const Eigen::Vector3d tcp = X_BinTcpLift.translation();
  Eigen::Vector3d target = -hold.p_TcpPayload_Bin;
  for (int axis = 0; axis < 2; ++axis) {
    const double reach = std::max(0.0, 0.5 * bin_inner_size[axis] - wall_margin);
    target[axis] = std::clamp(target[axis], -reach, reach);
  }
  hold.shift_Bin = Eigen::Vector3d(target.x() - tcp.x(), target.y() - tcp.y(), 0.0);
  return hold;
}

Payload PayloadOnTool(const Wrench& reference, const Wrench& now, const Eigen::Matrix3d& R_BinTcp) {
  RequireFiniteVector(reference.force, "reference.force");
  RequireFiniteVector(reference.torque, "reference.torque");
  RequireFiniteVector(now.force, "now.force");
  RequireFiniteVector(now.torque, "now.torque");
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = R_BinTcp;
  RequireRigid(X, "R_BinTcp");
  const Eigen::Vector3d force_Bin = R_BinTcp * (now.force - reference.force);
  const Eigen::Vector3d torque_Bin = R_BinTcp * (now.torque - reference.torque);
  Payload payload;
  payload.weight = -force_Bin.z();
  // A load W at r below the sensor reads ΔM = r × (0, 0, −W): r_x = ΔM_y / W, r_y = −ΔM_x / W.
  if (payload.weight > 0.0)
    payload.p_TcpPayload_Bin = Eigen::Vector3d(torque_Bin.y(), -torque_Bin.x(), 0.0) / payload.weight;
  return payload;
}

bool HangsFromTheTool(const Payload& payload, double tube_length) {
  return !(tube_length > 0.0) || payload.p_TcpPayload_Bin.norm() <= tube_length;
}

Eigen::Vector3d PlanPutBackShift(const Eigen::Vector3d& p_Bin_tcp, const Eigen::Vector3d& p_TcpPayload_Bin,
                                 const Eigen::Vector3d& bin_inner_size, double margin) {
  RequireFiniteVector(p_Bin_tcp, "p_Bin_tcp");
  RequireFiniteVector(p_TcpPayload_Bin, "p_TcpPayload_Bin");
  RequireFiniteVector(bin_inner_size, "bin_inner_size");
  RequireNonNegative(margin, "put_back_margin");
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  for (int axis = 0; axis < 2; ++axis) {
    const double reach = std::max(0.0, 0.5 * bin_inner_size[axis] - margin);
    const double centre = p_Bin_tcp[axis] + p_TcpPayload_Bin[axis];
    shift[axis] = std::clamp(centre, -reach, reach) - centre;
    // The TCP itself never goes further out than it was or than `reach`: a reading that puts the
    // centre of mass far past a wall (something pulling on the payload) must not carry the tool
    // over the opposite one.
    const double bound = std::max(std::abs(p_Bin_tcp[axis]), reach);
    shift[axis] = std::clamp(p_Bin_tcp[axis] + shift[axis], -bound, bound) - p_Bin_tcp[axis];
  }
  return shift;
}

}  // namespace tubepick
