#pragma once
/// \file
/// \brief HMAC-SHA256 (RFC 2104 / FIPS 198-1) over OpenSSL libcrypto, and a constant-time
/// tag comparison. The only place the comm module touches OpenSSL.
/// Thread safety: all functions are reentrant (OpenSSL 3 is thread-safe for these calls).

#include <array>
#include <cstddef>
#include <cstdint>

namespace gesture_formation::comm {

/// \brief Length of a pre-shared key and of a tag [bytes] (SHA-256 output).
constexpr std::size_t kKeyBytes = 32;
constexpr std::size_t kTagBytes = 32;

using Tag = std::array<std::uint8_t, kTagBytes>;

/// \brief tag = HMAC-SHA256(key, data). Returns false only if OpenSSL fails (then `tag` is
/// zeroed, which never verifies against a real tag by chance with any useful probability).
bool hmacSha256(const std::uint8_t* key, std::size_t key_bytes, const std::uint8_t* data, std::size_t data_bytes,
                Tag& tag);

/// \brief Compares `n` bytes in time independent of their contents (CRYPTO_memcmp).
bool constantTimeEqual(const std::uint8_t* a, const std::uint8_t* b, std::size_t n);

/// \brief Overwrites memory in a way the compiler may not optimise away (OPENSSL_cleanse).
void secureZero(void* p, std::size_t n);

}  // namespace gesture_formation::comm
