#pragma once

#include <string>
#include <string_view>

#include "core/common/types.h"

namespace tubepick {

/// The wire form of a cloud (tubepick.v1.PointCloud.xyz): packed little-endian float32 x, y, z, 12 bytes
/// a point, whatever the host's byte order.
std::string PackXyz(const Points& points);

/// The inverse of PackXyz. @pre xyz.size() is a multiple of 12 (the server checks and names the field
/// first; see server/request_validation.h CheckCloudBytes). The server itself never decodes: modeling
/// reads the bytes in place (core/modeling/cloud_prepare.h PackedXyz).
Points UnpackXyz(std::string_view xyz);

}  // namespace tubepick
