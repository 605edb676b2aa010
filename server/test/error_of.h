#pragma once

#include "core/testing/error_of.h"

namespace tubepick::server {

using tubepick::testing::ErrorOf;

}  // namespace tubepick::server
