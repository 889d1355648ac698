// comm::MapUpdate (MessageType 11, docs/security.md §3.2 "map_update"): the codec round-trips and
// has the documented size; every refusal names its field, in the encoder and the decoder alike;
// the receiver's check refuses a wrong resolution and a key outside its grid.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "gesture_formation/comm/map_update.hpp"

namespace gf = gesture_formation;
using gf::comm::MapUpdate;
using gf::comm::PayloadError;

namespace {

MapUpdate sample() {
  MapUpdate m;
  m.uav_index = 2;
  m.sequence = 41;
  m.delta.stamp_s = 17.25;
  m.delta.resolution_m = 0.2;
  m.delta.occupied = {{{32770, 32771, 32769}}, {{32790, 32768, 32800}}};
  m.delta.free = {{{32769, 32769, 32769}}};
  return m;
}

gf::mapping::KeyGrid grid() {
  gf::mapping::KeyGrid g;
  g.resolution_m = 0.2;
  g.min_key = {{32700, 32700, 32768}};
  g.max_key = {{32900, 32900, 32850}};
  return g;
}

PayloadError decode(const std::vector<std::uint8_t>& b, MapUpdate& out, std::string& reason) {
  return gf::comm::decodePayload(b.data(), b.size(), out, &reason);
}

}  // namespace

TEST(MapUpdateTest, RoundTripsWithTheDocumentedSize) {
  const MapUpdate m = sample();
  const auto bytes = gf::comm::encodePayload(m);
  ASSERT_TRUE(static_cast<bool>(bytes)) << bytes.reason();
  EXPECT_EQ(bytes->size(), gf::mapping::kMapUpdateHeaderBytes + 3 * gf::mapping::kMapUpdateKeyBytes);
  EXPECT_EQ(gf::mapping::mapUpdateWireBytes(3), bytes->size() + 28 + 64);
  // Big-endian header: uav index, then the sequence.
  EXPECT_EQ((*bytes)[0], 0);
  EXPECT_EQ((*bytes)[1], 2);
  EXPECT_EQ((*bytes)[5], 41);
  MapUpdate out;
  std::string reason;
  ASSERT_EQ(decode(*bytes, out, reason), PayloadError::kNone) << reason;
  EXPECT_EQ(out.uav_index, m.uav_index);
  EXPECT_EQ(out.sequence, m.sequence);
  EXPECT_EQ(out.delta.stamp_s, m.delta.stamp_s);
  EXPECT_EQ(out.delta.resolution_m, m.delta.resolution_m);
  EXPECT_EQ(out.delta.occupied, m.delta.occupied);
  EXPECT_EQ(out.delta.free, m.delta.free);
  EXPECT_EQ(gf::comm::checkMapUpdate(out, grid(), &reason), PayloadError::kNone) << reason;
  // An empty update is valid too (nothing changed).
  MapUpdate empty = sample();
  empty.delta.occupied.clear();
  empty.delta.free.clear();
  const auto e = gf::comm::encodePayload(empty);
  ASSERT_TRUE(static_cast<bool>(e));
  EXPECT_EQ(e->size(), gf::mapping::kMapUpdateHeaderBytes);
  EXPECT_EQ(decode(*e, out, reason), PayloadError::kNone) << reason;
  EXPECT_EQ(out.delta.size(), 0u);
}

TEST(MapUpdateTest, TheLargestUpdateFitsAndOneMoreKeyIsRefused) {
  MapUpdate m = sample();
  m.delta.occupied.clear();
  m.delta.free.clear();
  for (std::size_t i = 0; i < gf::mapping::kMaxMapUpdateVoxels; ++i) {
    m.delta.occupied.push_back({{static_cast<std::uint16_t>(32768 + i % 100), static_cast<std::uint16_t>(32768 + i / 100), 32768}});
  }
  const auto bytes = gf::comm::encodePayload(m);
  ASSERT_TRUE(static_cast<bool>(bytes)) << bytes.reason();
  EXPECT_LE(bytes->size(), gf::comm::kMaxPayloadBytes);
  MapUpdate out;
  std::string reason;
  EXPECT_EQ(decode(*bytes, out, reason), PayloadError::kNone) << reason;
  m.delta.free.push_back({{1, 1, 1}});
  const auto over = gf::comm::encodePayload(m);
  ASSERT_FALSE(static_cast<bool>(over));
  EXPECT_NE(over.reason().find("map_update.occupied + free count 8193 is over the limit 8192"), std::string::npos)
      << over.reason();
  // The decoder refuses the count from the header alone (before reading any key).
  std::vector<std::uint8_t> header(bytes->begin(), bytes->begin() + gf::mapping::kMapUpdateHeaderBytes);
  header[24] = 0x00;
  header[25] = 0x01;  // one free key more than the limit, and no keys at all after the header
  out = sample();
  EXPECT_EQ(decode(header, out, reason), PayloadError::kOversizeArray);
  EXPECT_NE(reason.find("occupied + free count 8193"), std::string::npos) << reason;
  EXPECT_EQ(out.sequence, 41u);  // untouched
}

TEST(MapUpdateTest, EveryMalformedPayloadIsRefusedNamingItsField) {
  const auto good = gf::comm::encodePayload(sample()).value();
  MapUpdate out;
  std::string reason;
  // Truncated: in the header, and in the keys.
  EXPECT_EQ(decode(std::vector<std::uint8_t>(good.begin(), good.begin() + 10), out, reason), PayloadError::kTruncated);
  EXPECT_NE(reason.find("map_update.header"), std::string::npos) << reason;
  EXPECT_EQ(decode(std::vector<std::uint8_t>(good.begin(), good.end() - 1), out, reason), PayloadError::kTruncated);
  EXPECT_NE(reason.find("map_update.keys"), std::string::npos) << reason;
  // Trailing bytes.
  auto longer = good;
  longer.push_back(0);
  EXPECT_EQ(decode(longer, out, reason), PayloadError::kTrailingBytes);
  EXPECT_NE(reason.find("after the last key"), std::string::npos) << reason;
  // Field by field, each refused by the encoder and by the decoder with the same field named.
  struct Case {
    const char* field;
    PayloadError error;
    void (*spoil)(MapUpdate&);
  };
  const Case cases[] = {
      {"map_update.uav_index", PayloadError::kOutOfRange, [](MapUpdate& m) { m.uav_index = 32; }},
      {"map_update.stamp_s", PayloadError::kNonFinite, [](MapUpdate& m) { m.delta.stamp_s = std::nan(""); }},
      {"map_update.stamp_s must be a time in [0, 4e9) s, got -1", PayloadError::kOutOfRange, [](MapUpdate& m) { m.delta.stamp_s = -1.0; }},
      {"map_update.stamp_s must be a time in [0, 4e9) s", PayloadError::kOutOfRange, [](MapUpdate& m) { m.delta.stamp_s = 5.0e9; }},
      {"map_update.resolution_m", PayloadError::kNonFinite,
       [](MapUpdate& m) { m.delta.resolution_m = std::numeric_limits<double>::infinity(); }},
      {"map_update.resolution_m", PayloadError::kOutOfRange, [](MapUpdate& m) { m.delta.resolution_m = 0.0; }},
      {"map_update.resolution_m", PayloadError::kOutOfRange, [](MapUpdate& m) { m.delta.resolution_m = 10.5; }},
      {"map_update.occupied[1] lists a key already listed", PayloadError::kOutOfRange,
       [](MapUpdate& m) { m.delta.occupied[1] = m.delta.occupied[0]; }},
      {"map_update.free[0] lists a key already listed", PayloadError::kOutOfRange,
       [](MapUpdate& m) { m.delta.free[0] = m.delta.occupied[1]; }},
  };
  for (const Case& c : cases) {
    MapUpdate bad = sample();
    c.spoil(bad);
    const auto enc = gf::comm::encodePayload(bad);
    ASSERT_FALSE(static_cast<bool>(enc)) << c.field;
    EXPECT_NE(enc.reason().find(c.field), std::string::npos) << enc.reason();
    // The same bytes written by hand (the encoder refuses them): header fields patched into `good`.
    auto bytes = good;
    const MapUpdate s = sample();
    if (bad.uav_index != s.uav_index) bytes[1] = static_cast<std::uint8_t>(bad.uav_index);
    auto putF64 = [&](std::size_t at, double v) {
      std::uint64_t bits = 0;
      std::memcpy(&bits, &v, sizeof bits);
      for (int i = 0; i < 8; ++i) bytes[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(bits >> (56 - 8 * i));
    };
    putF64(6, bad.delta.stamp_s);
    putF64(14, bad.delta.resolution_m);
    std::size_t at = gf::mapping::kMapUpdateHeaderBytes;
    for (const auto* list : {&bad.delta.occupied, &bad.delta.free}) {
      for (const auto& k : *list) {
        for (int a = 0; a < 3; ++a, at += 2) {
          bytes[at] = static_cast<std::uint8_t>(k[static_cast<std::size_t>(a)] >> 8);
          bytes[at + 1] = static_cast<std::uint8_t>(k[static_cast<std::size_t>(a)] & 0xff);
        }
      }
    }
    out = sample();
    out.sequence = 999;
    EXPECT_EQ(decode(bytes, out, reason), c.error) << c.field;
    EXPECT_NE(reason.find(c.field), std::string::npos) << reason;
    EXPECT_EQ(out.sequence, 999u) << "the output is written only on success";
  }
}

TEST(MapUpdateTest, TheReceiverRefusesAnotherResolutionAndKeysOutsideItsGrid) {
  std::string reason;
  MapUpdate m = sample();
  m.delta.resolution_m = 0.4;
  EXPECT_EQ(gf::comm::checkMapUpdate(m, grid(), &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("map_update.resolution_m 0.400000 differs from the map's 0.200000"), std::string::npos) << reason;
  m = sample();
  m.delta.free[0][2] = 32767;  // below the grid's lowest z key
  EXPECT_EQ(gf::comm::checkMapUpdate(m, grid(), &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("map_update.free[0] key (32769, 32769, 32767) is outside the map's keys"), std::string::npos) << reason;
  m = sample();
  m.delta.occupied[1][0] = 32901;
  EXPECT_EQ(gf::comm::checkMapUpdate(m, grid(), &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("map_update.occupied[1]"), std::string::npos) << reason;
}

TEST(MapUpdateTest, TheDecoderChecksTheEnvelopeType) {
  gf::comm::Envelope e;
  e.type = gf::comm::MessageType::kMapUpdate;
  e.payload = gf::comm::encodePayload(sample()).value();
  gf::comm::PayloadDecoder decoder;
  MapUpdate out;
  EXPECT_TRUE(decoder.decode(e, out));
  EXPECT_EQ(out.sequence, 41u);
  EXPECT_STREQ(gf::comm::toString(gf::comm::MessageType::kMapUpdate), "map_update");
  EXPECT_EQ(static_cast<int>(gf::comm::MessageType::kMapUpdate), 11);
  e.type = gf::comm::MessageType::kHeartbeat;
  EXPECT_FALSE(decoder.decode(e, out));
  EXPECT_EQ(decoder.counters().count(PayloadError::kWrongType), 1u);
}
