#include "gesture_formation/comm/hmac.hpp"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>

namespace gesture_formation::comm {

bool hmacSha256(const std::uint8_t* key, std::size_t key_bytes, const std::uint8_t* data, std::size_t data_bytes,
                Tag& tag) {
  unsigned int tag_len = 0;
  // HMAC() rejects a NULL data pointer on some OpenSSL versions even for zero length.
  static const std::uint8_t kEmpty = 0;
  const unsigned char* out = HMAC(EVP_sha256(), key, static_cast<int>(key_bytes), data_bytes ? data : &kEmpty,
                                  data_bytes, tag.data(), &tag_len);
  if (out == nullptr || tag_len != kTagBytes) {
    tag.fill(0);
    return false;
  }
  return true;
}

bool constantTimeEqual(const std::uint8_t* a, const std::uint8_t* b, std::size_t n) {
  return CRYPTO_memcmp(a, b, n) == 0;
}

void secureZero(void* p, std::size_t n) { OPENSSL_cleanse(p, n); }

}  // namespace gesture_formation::comm
