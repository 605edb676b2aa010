#pragma once

// Whether this build is instrumented by a sanitizer (deploy/ci/sanitizers.sh), for tests with
// wall-clock bounds: our instrumented code runs several times slower there (ASan ~3x, TSan ~10x),
// while the libraries we do not build (Bullet, gRPC) keep their speed.

namespace tubepick::testing {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)  // gcc
inline constexpr bool kSanitizerBuild = true;
#elif defined(__has_feature)  // clang
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
inline constexpr bool kSanitizerBuild = true;
#else
inline constexpr bool kSanitizerBuild = false;
#endif
#else
inline constexpr bool kSanitizerBuild = false;
#endif

/// Factor for a test's wall-clock bounds: 1 in a normal build, 10 under a sanitizer.
inline constexpr int kTimeScale = kSanitizerBuild ? 10 : 1;

}  // namespace tubepick::testing
