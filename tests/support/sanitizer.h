// Whether the tests run in the sanitizer build (FIELDRIG_SANITIZE, scripts/test-sanitize.sh), for
// the few tests that cannot work there; each says why when it skips.
#pragma once

namespace fieldrig::testing_support {

// GCC and Clang define __SANITIZE_ADDRESS__ under -fsanitize=address. AddressSanitizer reserves
// terabytes of address space for its shadow memory at start, so a program run under an
// address-space limit (ulimit -v) cannot start at all.
inline constexpr bool kAddressSanitizer =
#if defined(__SANITIZE_ADDRESS__)
    true;
#else
    false;
#endif

}  // namespace fieldrig::testing_support
