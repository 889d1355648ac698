#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "comm_test_util.hpp"
#include "gesture_formation/comm/envelope.hpp"
#include "gesture_formation/comm/signer.hpp"

using namespace gesture_formation::comm;
namespace t = gesture_formation::comm::testing;

namespace {

Envelope sample() {
  Envelope e;
  e.type = MessageType::kWorkerState;
  e.sender_id = 0x0102;
  e.key_id = 7;
  e.sequence = 0x1122334455667788ull;
  e.stamp_s = 1.5;
  e.payload = {0xAA, 0xBB, 0xCC};
  return e;
}

std::vector<std::uint8_t> sealSample(const Envelope& e) {
  const auto k = t::keyBytes(3);
  auto sealed = sealEnvelope(e, k.data(), k.size());
  EXPECT_TRUE(sealed) << sealed.reason();
  return sealed.value();
}

}  // namespace

TEST(CommEnvelopeTest, LayoutMatchesTheDocumentedByteTable) {
  const Envelope e = sample();
  const std::vector<std::uint8_t> b = sealSample(e);
  ASSERT_EQ(b.size(), kHeaderBytes + 3 + kTagBytes);
  EXPECT_EQ(b[0], 0x47);
  EXPECT_EQ(b[1], 0x46);
  EXPECT_EQ(b[2], kEnvelopeVersion);
  EXPECT_EQ(b[3], 2);  // worker state
  EXPECT_EQ(b[4], 0x01);
  EXPECT_EQ(b[5], 0x02);  // sender id big-endian
  EXPECT_EQ(b[6], 7);     // key id
  EXPECT_EQ(b[7], 0);     // flags
  const std::uint8_t seq[8] = {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88};
  EXPECT_EQ(0, std::memcmp(&b[8], seq, 8));
  const std::uint8_t stamp[8] = {0x3F, 0xF8, 0, 0, 0, 0, 0, 0};  // 1.5 as binary64 big-endian
  EXPECT_EQ(0, std::memcmp(&b[16], stamp, 8));
  EXPECT_EQ(b[24], 0);
  EXPECT_EQ(b[25], 0);
  EXPECT_EQ(b[26], 0);
  EXPECT_EQ(b[27], 3);
  EXPECT_EQ(b[28], 0xAA);
  // Tag: HMAC-SHA256 over bytes 0..30, recomputed independently.
  Tag tag{};
  const auto k = t::keyBytes(3);
  ASSERT_TRUE(hmacSha256(k.data(), k.size(), b.data(), kHeaderBytes + 3, tag));
  EXPECT_EQ(0, std::memcmp(tag.data(), &b[kHeaderBytes + 3], kTagBytes));
}

TEST(CommEnvelopeTest, HmacMatchesRfc4231TestCase2) {
  // RFC 4231 test case 2: key "Jefe", data "what do ya want for nothing?".
  const std::string key = "Jefe";
  const std::string data = "what do ya want for nothing?";
  Tag tag{};
  ASSERT_TRUE(hmacSha256(reinterpret_cast<const std::uint8_t*>(key.data()), key.size(),
                         reinterpret_cast<const std::uint8_t*>(data.data()), data.size(), tag));
  const std::uint8_t expected[32] = {0x5b, 0xdc, 0xc1, 0x46, 0xbf, 0x60, 0x75, 0x4e, 0x6a, 0x04, 0x24,
                                     0x26, 0x08, 0x95, 0x75, 0xc7, 0x5a, 0x00, 0x3f, 0x08, 0x9d, 0x27,
                                     0x39, 0x83, 0x9d, 0xec, 0x58, 0xb9, 0x64, 0xec, 0x38, 0x43};
  EXPECT_EQ(0, std::memcmp(tag.data(), expected, 32));
}

TEST(CommEnvelopeTest, ParseRoundTripsEveryField) {
  const Envelope e = sample();
  const auto b = sealSample(e);
  EnvelopeView v;
  ASSERT_EQ(parseEnvelope(b.data(), b.size(), v), EnvelopeError::kNone);
  EXPECT_EQ(v.type, e.type);
  EXPECT_EQ(v.sender_id, e.sender_id);
  EXPECT_EQ(v.key_id, e.key_id);
  EXPECT_EQ(v.sequence, e.sequence);
  EXPECT_EQ(v.stamp_s, e.stamp_s);
  ASSERT_EQ(v.payload_bytes, 3u);
  EXPECT_EQ(v.payload[2], 0xCC);
  EXPECT_EQ(v.signed_size, kHeaderBytes + 3);
  EXPECT_EQ(v.tag, b.data() + kHeaderBytes + 3);
}

TEST(CommEnvelopeTest, StructuralErrorsAreNamed) {
  const auto good = sealSample(sample());
  EnvelopeView v;
  auto check = [&](std::vector<std::uint8_t> b, EnvelopeError expected) {
    EnvelopeView before = v;
    EXPECT_EQ(parseEnvelope(b.data(), b.size(), v), expected) << toString(expected);
    EXPECT_EQ(v.payload, before.payload);  // untouched on error
  };
  check({}, EnvelopeError::kTruncated);
  check(std::vector<std::uint8_t>(good.begin(), good.begin() + 59), EnvelopeError::kTruncated);
  check(std::vector<std::uint8_t>(good.begin(), good.end() - 1), EnvelopeError::kTruncated);
  auto b = good;
  b.push_back(0);
  check(b, EnvelopeError::kLengthMismatch);
  b = good;
  b[0] = 'X';
  check(b, EnvelopeError::kBadMagic);
  b = good;
  b[2] = 3;  // 1 and 2 are versions
  check(b, EnvelopeError::kBadVersion);
  b = good;
  b[3] = 0;
  check(b, EnvelopeError::kBadType);
  b[3] = kMaxMessageType + 1;
  check(b, EnvelopeError::kBadType);
  b = good;
  b[7] = 1;
  check(b, EnvelopeError::kBadFlags);
  b = good;
  b[24] = 0x7F;  // length 2 GB
  check(b, EnvelopeError::kOversize);
  check(std::vector<std::uint8_t>(kMaxEnvelopeBytes + 1, 0), EnvelopeError::kOversize);
  // The stamp must be a wire time (a ROS time can hold it): finite, in [0, kMaxWireTimeS).
  for (const double stamp : {std::numeric_limits<double>::quiet_NaN(), -1.0, -1e-9, kMaxWireTimeS, 5.0e9}) {
    b = good;
    std::uint64_t bits = 0;
    std::memcpy(&bits, &stamp, 8);
    for (int i = 0; i < 8; ++i) b[16 + i] = static_cast<std::uint8_t>(bits >> (56 - 8 * i));
    check(b, EnvelopeError::kBadStamp);
  }
  EXPECT_EQ(parseEnvelope(nullptr, 100, v), EnvelopeError::kTruncated);
}

TEST(CommEnvelopeTest, SealRefusesWhatReceiversWouldRefuse) {
  const auto k = t::keyBytes(1);
  Envelope e = sample();
  e.payload.assign(kMaxPayloadBytes + 1, 0);
  EXPECT_FALSE(sealEnvelope(e, k.data(), k.size()));
  e.payload.assign(kMaxPayloadBytes, 0);
  auto max = sealEnvelope(e, k.data(), k.size());
  ASSERT_TRUE(max);
  EXPECT_EQ(max->size(), kHeaderBytes + kMaxPayloadBytes + kTagBytes);  // version 1
  EXPECT_EQ(kMaxEnvelopeBytes, kHeaderBytes + kMaxPayloadBytes + kEd25519SignatureBytes);
  e.payload.clear();
  for (const double stamp : {std::numeric_limits<double>::infinity(), -1.0, kMaxWireTimeS}) {
    e.stamp_s = stamp;
    const auto sealed = sealEnvelope(e, k.data(), k.size());
    ASSERT_FALSE(sealed) << stamp;
    EXPECT_NE(sealed.reason().find("stamp_s must be a time in [0, 4e9) s"), std::string::npos) << sealed.reason();
  }
  e.stamp_s = 0;
  e.type = static_cast<MessageType>(kMaxMessageType + 1);  // the first unknown type
  EXPECT_FALSE(sealEnvelope(e, k.data(), k.size()));
}

TEST(CommSignerTest, SequenceIncreasesOnlyOnSuccessAndUsesTheActiveKey) {
  Signer s(5, t::ring({t::keyEntry(1, 10), t::keyEntry(2, 20)}, 2), 100);
  auto a = s.seal(MessageType::kHeartbeat, {1, 2}, 0.0);
  ASSERT_TRUE(a);
  EXPECT_EQ(s.nextSequence(), 101u);
  EXPECT_FALSE(s.seal(MessageType::kHeartbeat, {}, std::nan("")));
  EXPECT_EQ(s.nextSequence(), 101u);
  EnvelopeView v;
  ASSERT_EQ(parseEnvelope(a->data(), a->size(), v), EnvelopeError::kNone);
  EXPECT_EQ(v.key_id, 2);
  EXPECT_EQ(v.sequence, 100u);
  EXPECT_EQ(v.sender_id, 5);
}

TEST(CommSignerTest, RefusesToWrapTheSequence) {
  Signer s(5, t::ring({t::keyEntry(1, 10)}, 1), std::numeric_limits<std::uint64_t>::max());
  EXPECT_TRUE(s.seal(MessageType::kHeartbeat, {}, 0.0));
  EXPECT_FALSE(s.seal(MessageType::kHeartbeat, {}, 0.0));
}
