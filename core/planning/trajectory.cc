#include "core/planning/trajectory.h"

namespace tubepick {

std::string ToString(TrajectoryKind kind) {
  switch (kind) {
    case TrajectoryKind::kUpward:
      return "upward";
    case TrajectoryKind::kEscape:
      return "escape";
    case TrajectoryKind::kOcclusionEscape:
      return "occlusion_escape";
  }
  return "unknown";
}

}  // namespace tubepick
