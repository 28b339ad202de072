// A design is known by its content, not its file name: the SHA-256 of the design file's bytes (OpenSSL's
// EVP digest), written as 64 lowercase hex digits. Two files with the same name and other bytes are two
// designs; a file edited in place is another design. Non-RT.
#pragma once

#include <string>
#include <string_view>

namespace loom::job {

// The SHA-256 of `bytes` as 64 lowercase hex digits.
std::string sha256_hex(std::string_view bytes);

// True when `text` is 64 lowercase hex digits (what sha256_hex writes).
bool is_sha256_hex(std::string_view text);

}  // namespace loom::job
