// SHA-256 as lowercase hex (OpenSSL's EVP): a session names its location map by it, and a batch
// plan its parameters and calibration files.
#pragma once

#include <string>
#include <string_view>

namespace fieldrig::recording {

// The SHA-256 of `bytes` as 64 lowercase hex digits; empty only if OpenSSL fails.
std::string sha256Hex(std::string_view bytes);

}  // namespace fieldrig::recording
