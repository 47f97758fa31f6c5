// Whether the tests were built with AddressSanitizer or ThreadSanitizer:
// some tests cannot run under them (real-time scheduling, an address-space
// limit the sanitizers' shadow memory exceeds).
#pragma once

namespace evlife::test {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool kSanitizerBuild = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
inline constexpr bool kSanitizerBuild = true;
#else
inline constexpr bool kSanitizerBuild = false;
#endif
#else
inline constexpr bool kSanitizerBuild = false;
#endif

}  // namespace evlife::test
