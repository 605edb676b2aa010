// A deliberate leak, to check that the soak's memory check catches one (docs/RELIABILITY.md):
// preloaded into tubepick-server, it drops every LEAK_EVERY-th release of a block of 1 MiB or more
// (default 100), so about one cloud-sized buffer in LEAK_EVERY stays resident. Both ways a block is
// released are caught: free() and C++'s operator delete, which jemalloc (the server's allocator)
// provides itself without going through free().
//
//   cc -O2 -shared -fPIC -o /tmp/leak-shim.so deploy/ci/leak-shim.c -ldl
//   LD_PRELOAD=/tmp/leak-shim.so LEAK_EVERY=250 BUILD_DIR=build bash deploy/ci/soak.sh   # must FAIL
//
// Not built by CMake and not part of any test run.
#define _GNU_SOURCE
#include <dlfcn.h>
#include <malloc.h>
#include <stdatomic.h>
#include <stdlib.h>

static atomic_ulong large_releases;
static unsigned long every;

// True when this release of `p` is the one in LEAK_EVERY to drop.
static int leak(void* p) {
  if (!every) {
    const char* e = getenv("LEAK_EVERY");
    every = e && strtoul(e, NULL, 10) > 0 ? strtoul(e, NULL, 10) : 100;
  }
  return p && malloc_usable_size(p) >= (1u << 20) && atomic_fetch_add(&large_releases, 1) % every == every - 1;
}

void free(void* p) {
  static void (*real)(void*);
  if (!real) real = (void (*)(void*))dlsym(RTLD_NEXT, "free");
  if (!leak(p)) real(p);
}

// operator delete(void*)
void _ZdlPv(void* p) {
  static void (*real)(void*);
  if (!real) real = (void (*)(void*))dlsym(RTLD_NEXT, "_ZdlPv");
  if (!leak(p)) real(p);
}

// operator delete(void*, std::size_t)
void _ZdlPvm(void* p, size_t size) {
  static void (*real)(void*, size_t);
  if (!real) real = (void (*)(void*, size_t))dlsym(RTLD_NEXT, "_ZdlPvm");
  if (!leak(p)) real(p, size);
}
