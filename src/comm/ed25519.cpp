#include "gesture_formation/comm/ed25519.hpp"

#include <openssl/evp.h>

#include <memory>

namespace gesture_formation::comm {

namespace {

struct PkeyDeleter {
  void operator()(EVP_PKEY* p) const { EVP_PKEY_free(p); }
};
struct MdCtxDeleter {
  void operator()(EVP_MD_CTX* p) const { EVP_MD_CTX_free(p); }
};
using PkeyPtr = std::unique_ptr<EVP_PKEY, PkeyDeleter>;
using MdCtxPtr = std::unique_ptr<EVP_MD_CTX, MdCtxDeleter>;

PkeyPtr privateKey(const std::uint8_t* seed) {
  return PkeyPtr(EVP_PKEY_new_raw_private_key(EVP_PKEY_ED25519, nullptr, seed, kEd25519SeedBytes));
}

}  // namespace

bool ed25519PublicFromSeed(const std::uint8_t* seed, PublicKey& pub) {
  pub.fill(0);
  const PkeyPtr key = privateKey(seed);
  std::size_t len = pub.size();
  if (!key || EVP_PKEY_get_raw_public_key(key.get(), pub.data(), &len) != 1 || len != pub.size()) {
    pub.fill(0);
    return false;
  }
  return true;
}

bool ed25519Sign(const std::uint8_t* seed, const std::uint8_t* data, std::size_t data_bytes, Signature& signature) {
  signature.fill(0);
  const PkeyPtr key = privateKey(seed);
  const MdCtxPtr ctx(EVP_MD_CTX_new());
  std::size_t len = signature.size();
  if (!key || !ctx || EVP_DigestSignInit(ctx.get(), nullptr, nullptr, nullptr, key.get()) != 1 ||
      EVP_DigestSign(ctx.get(), signature.data(), &len, data, data_bytes) != 1 || len != signature.size()) {
    signature.fill(0);
    return false;
  }
  return true;
}

bool ed25519Verify(const PublicKey& pub, const std::uint8_t* data, std::size_t data_bytes,
                   const std::uint8_t* signature) {
  const PkeyPtr key(EVP_PKEY_new_raw_public_key(EVP_PKEY_ED25519, nullptr, pub.data(), pub.size()));
  const MdCtxPtr ctx(EVP_MD_CTX_new());
  return key && ctx && EVP_DigestVerifyInit(ctx.get(), nullptr, nullptr, nullptr, key.get()) == 1 &&
         EVP_DigestVerify(ctx.get(), signature, kEd25519SignatureBytes, data, data_bytes) == 1;
}

}  // namespace gesture_formation::comm
