#pragma once
/// \file
/// \brief Ed25519 signatures (RFC 8032, PureEdDSA) over OpenSSL libcrypto's EVP interface:
/// the per-sender signatures of envelope version 2 (docs/security.md §5). A node signs with
/// its own 32-byte secret seed; every receiver holds only the senders' public keys, so a
/// captured node cannot sign for another.
/// Thread safety: all functions are reentrant.

#include <array>
#include <cstddef>
#include <cstdint>

namespace gesture_formation::comm {

constexpr std::size_t kEd25519SeedBytes = 32;       ///< secret key (RFC 8032 "private key")
constexpr std::size_t kEd25519PublicKeyBytes = 32;
constexpr std::size_t kEd25519SignatureBytes = 64;

using PublicKey = std::array<std::uint8_t, kEd25519PublicKeyBytes>;
using Signature = std::array<std::uint8_t, kEd25519SignatureBytes>;

/// \brief The public key of a secret seed. False only if OpenSSL fails (`pub` zeroed).
bool ed25519PublicFromSeed(const std::uint8_t* seed, PublicKey& pub);

/// \brief signature = Ed25519-Sign(seed, data). False only if OpenSSL fails (`signature` zeroed).
bool ed25519Sign(const std::uint8_t* seed, const std::uint8_t* data, std::size_t data_bytes, Signature& signature);

/// \brief True iff `signature` (kEd25519SignatureBytes) is a valid signature of `data` by `pub`.
bool ed25519Verify(const PublicKey& pub, const std::uint8_t* data, std::size_t data_bytes,
                   const std::uint8_t* signature);

}  // namespace gesture_formation::comm
