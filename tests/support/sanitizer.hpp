// Memory-footprint tests measure the process's resident set, which AddressSanitizer inflates on purpose
// (freed blocks are quarantined, every allocation carries redzones): they are run in the plain build only.
#pragma once

#if defined(__SANITIZE_ADDRESS__)
#define LOOM_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define LOOM_UNDER_ASAN 1
#endif
#endif

#if defined(LOOM_UNDER_ASAN)
#define LOOM_SKIP_MEMORY_FOOTPRINT_UNDER_ASAN() \
  GTEST_SKIP() << "resident memory is not meaningful under AddressSanitizer (quarantine, redzones)"
#else
#define LOOM_SKIP_MEMORY_FOOTPRINT_UNDER_ASAN() static_cast<void>(0)
#endif
