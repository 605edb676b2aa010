#include "clients/cell/cell_fault.h"

#include <fmt/core.h>

namespace tubepick::cell {

std::string ToString(FaultKind kind) {
  switch (kind) {
    case FaultKind::kTimeout:
      return "timeout";
    case FaultKind::kDeviceFault:
      return "device_fault";
    case FaultKind::kServerUnavailable:
      return "server_unavailable";
    case FaultKind::kServerError:
      return "server_error";
    case FaultKind::kUnexpectedLoad:
      return "unexpected_load";
    case FaultKind::kInternal:
      return "internal";
  }
  return "internal";
}

CellFault::CellFault(std::string device, FaultKind kind, std::string state, std::string error)
    : std::runtime_error(fmt::format("{} {} during {}: {}", device, ToString(kind), state, error)),
      device_(std::move(device)),
      kind_(kind),
      state_(std::move(state)),
      error_(std::move(error)) {}

}  // namespace tubepick::cell
