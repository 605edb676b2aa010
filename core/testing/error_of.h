#pragma once

#include <gtest/gtest.h>

#include <string>

#include "core/common/errors.h"

namespace tubepick::testing {

/// Runs `f` and returns the InvalidArgument message (fails the test when nothing is thrown).
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected InvalidArgument";
  return "";
}

}  // namespace tubepick::testing
