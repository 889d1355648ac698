#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <map>
#include <random>
#include <set>
#include <utility>

#include "comm_test_util.hpp"
#include "gesture_formation/comm/signer.hpp"
#include "gesture_formation/comm/verifier.hpp"
#include "gesture_formation/common/config_fields.hpp"

using namespace gesture_formation::comm;
namespace t = gesture_formation::comm::testing;

namespace {

constexpr std::uint8_t kGoodKey = 10;  // fill byte of the shared key
constexpr std::uint8_t kEvilKey = 99;  // an attacker's key

VerifierConfig config() {
  VerifierConfig c;
  c.known_senders = {1, 2, 3};
  c.own_sender_id = 9;
  c.max_age_s = 1.0;
  c.max_future_s = 0.25;
  c.replay_window = 1024;
  c.burst = 1e9;  // these tests send thousands at one instant; the budget: test_link_state.cpp
  return c;
}

Verifier makeVerifier(const VerifierConfig& c = config(), KeyRing keys = t::ring({t::keyEntry(1, kGoodKey)}, 1)) {
  auto v = Verifier::create(c, std::move(keys));
  EXPECT_TRUE(v) << v.reason();
  return std::move(v.value());
}

std::vector<std::uint8_t> seal(std::uint16_t sender, std::uint64_t sequence, double stamp_s,
                               std::uint8_t key_fill = kGoodKey, std::uint8_t key_id = 1,
                               MessageType type = MessageType::kHeartbeat, std::vector<std::uint8_t> payload = {1, 2, 3}) {
  Envelope e;
  e.type = type;
  e.sender_id = sender;
  e.key_id = key_id;
  e.sequence = sequence;
  e.stamp_s = stamp_s;
  e.payload = std::move(payload);
  const auto k = t::keyBytes(key_fill);
  return sealEnvelope(e, k.data(), k.size()).value();
}

Verdict verify(Verifier& v, const std::vector<std::uint8_t>& b, double now) { return v.verify(b.data(), b.size(), now).verdict; }

}  // namespace

TEST(CommVerifierTest, AcceptsAnAuthenticEnvelopeAndReturnsIt) {
  Verifier v = makeVerifier();
  Signer s(2, t::ring({t::keyEntry(1, kGoodKey)}, 1), 41);
  auto b = s.seal(MessageType::kFormationCommand, {9, 8, 7}, 100.0);
  ASSERT_TRUE(b);
  VerifyResult r = v.verify(b->data(), b->size(), 100.2);
  ASSERT_TRUE(r.accepted()) << toString(r.verdict) << " " << r.detail;
  EXPECT_EQ(r.envelope.type, MessageType::kFormationCommand);
  EXPECT_EQ(r.envelope.sender_id, 2);
  EXPECT_EQ(r.envelope.sequence, 41u);
  EXPECT_EQ(r.envelope.stamp_s, 100.0);
  EXPECT_EQ(r.envelope.payload, (std::vector<std::uint8_t>{9, 8, 7}));
  EXPECT_EQ(v.counters().accepted(), 1u);
  EXPECT_EQ(v.counters().total(), 1u);
}

TEST(CommVerifierTest, EachRejectionHasItsVerdictAndCounter) {
  Verifier v = makeVerifier();
  const double now = 50.0;
  auto good = seal(1, 10, now);
  std::vector<std::pair<std::vector<std::uint8_t>, Verdict>> cases;
  cases.push_back({std::vector<std::uint8_t>(good.begin(), good.end() - 1), Verdict::kTruncated});
  cases.push_back({std::vector<std::uint8_t>(kMaxEnvelopeBytes + 1, 0x47), Verdict::kOversize});
  auto b = good;
  b[2] = 9;
  cases.push_back({b, Verdict::kBadVersion});
  b = good;
  b[3] = 77;
  cases.push_back({b, Verdict::kBadType});
  b = good;
  b[1] = 0;
  cases.push_back({b, Verdict::kMalformed});
  cases.push_back({seal(9, 10, now), Verdict::kOwnMessage});
  cases.push_back({seal(4, 10, now), Verdict::kUnknownSender});
  cases.push_back({seal(1, 10, now, kGoodKey, 2), Verdict::kUnknownKey});
  cases.push_back({seal(1, 10, now, kEvilKey), Verdict::kForged});
  b = good;
  b[kHeaderBytes] ^= 0x01;  // payload bit
  cases.push_back({b, Verdict::kForged});
  b = good;
  b.back() ^= 0x80;  // tag bit
  cases.push_back({b, Verdict::kForged});
  cases.push_back({seal(1, 10, now - 1.001), Verdict::kTooOld});
  cases.push_back({seal(1, 10, now + 0.26), Verdict::kTooNew});
  for (const auto& [bytes, verdict] : cases) {
    const VerifierCounters before = v.counters();
    EXPECT_EQ(verify(v, bytes, now), verdict) << toString(verdict);
    EXPECT_EQ(v.counters().count(verdict), before.count(verdict) + 1) << toString(verdict);
    EXPECT_EQ(v.counters().total(), before.total() + 1);
  }
  // None of those changed sender 1's window: sequence 10 is still new.
  EXPECT_TRUE(v.window(1)->empty());
  EXPECT_EQ(verify(v, good, now), Verdict::kAccepted);
  EXPECT_EQ(verify(v, good, now), Verdict::kReplayed);
  EXPECT_EQ(verify(v, seal(1, 2000, now), now), Verdict::kAccepted);
  EXPECT_EQ(verify(v, seal(1, 11, now), now), Verdict::kStale);  // below 2000 − 1024
  EXPECT_EQ(v.counters().accepted(), 2u);
  EXPECT_EQ(v.counters().rejected(), cases.size() - 1 + 2);  // own message is not a rejection
}

TEST(CommVerifierTest, AgeLimitsPerTypeAndNonFiniteNow) {
  VerifierConfig c = config();
  c.max_age_s_by_type[MessageType::kFormationCommand] = 5.0;
  Verifier v = makeVerifier(c);
  EXPECT_EQ(verify(v, seal(1, 1, 0.0, kGoodKey, 1, MessageType::kFormationCommand), 4.9), Verdict::kAccepted);
  EXPECT_EQ(verify(v, seal(1, 2, 0.0, kGoodKey, 1, MessageType::kHeartbeat), 4.9), Verdict::kTooOld);
  EXPECT_EQ(verify(v, seal(1, 3, 0.0), std::nan("")), Verdict::kTooOld);
  EXPECT_EQ(verify(v, seal(1, 4, 0.0), 1.0), Verdict::kAccepted);   // age exactly max_age
  EXPECT_EQ(verify(v, seal(1, 5, 1.25), 1.0), Verdict::kAccepted);  // exactly max_future
}

TEST(CommVerifierTest, ConfigValidationNamesFields) {
  VerifierConfig c;
  c.max_age_s = 0;
  c.max_future_s = -1;
  c.replay_window = 10;
  c.known_senders = {1, 1};
  c.own_sender_id = 1;
  c.max_age_s_by_type[MessageType::kHeartbeat] = -2;
  const auto e = c.validate();
  const std::string all = [&] {
    std::string s;
    for (const auto& x : e) s += x + "\n";
    return s;
  }();
  for (const char* field : {"known_senders lists sender id 1 twice", "own_sender_id", "max_age_s must", "max_future_s",
                            "max_age_s_by_type.heartbeat", "replay_window"}) {
    EXPECT_NE(all.find(field), std::string::npos) << field << "\n" << all;
  }
  EXPECT_FALSE(Verifier::create(c, t::ring({t::keyEntry(1, 1)}, 1)));
  EXPECT_FALSE(Verifier::create(VerifierConfig{}, t::ring({t::keyEntry(1, 1)}, 1)));  // no senders
}

TEST(CommVerifierTest, AcceptsReorderedPacketsWithinTheWindowOnce) {
  Verifier v = makeVerifier();
  std::vector<std::vector<std::uint8_t>> packets;
  for (std::uint64_t s = 1; s <= 3000; ++s) packets.push_back(seal(1, s, 10.0));
  // Shuffle within blocks of 1000: every packet arrives less than the window (1024) late.
  std::mt19937_64 rng(7);
  for (std::size_t b = 0; b < packets.size(); b += 1000) {
    std::shuffle(packets.begin() + static_cast<long>(b), packets.begin() + static_cast<long>(b + 1000), rng);
  }
  for (const auto& p : packets) ASSERT_EQ(verify(v, p, 10.0), Verdict::kAccepted);
  for (std::size_t i = 2000; i < 3000; ++i) EXPECT_EQ(verify(v, packets[i], 10.0), Verdict::kReplayed);
  EXPECT_EQ(v.counters().accepted(), 3000u);
  EXPECT_EQ(v.counters().count(Verdict::kReplayed), 1000u);
}

TEST(CommVerifierTest, KeyRotationAcceptsBothKeysDuringTheWindowOnly) {
  // Phase 1: everyone on key 1. Phase 2 (file: "1 … accept_until_s=100", "2 … active").
  Signer old_sender(1, t::ring({t::keyEntry(1, 11)}, 1), 1);
  Signer new_sender(2, t::ring({t::keyEntry(1, 11, 100.0), t::keyEntry(2, 22)}, 2), 1);
  Verifier v = makeVerifier(config(), t::ring({t::keyEntry(1, 11, 100.0), t::keyEntry(2, 22)}, 2));
  EXPECT_EQ(verify(v, old_sender.seal(MessageType::kHeartbeat, {}, 99.0).value(), 99.0), Verdict::kAccepted);
  EXPECT_EQ(verify(v, new_sender.seal(MessageType::kHeartbeat, {}, 99.0).value(), 99.0), Verdict::kAccepted);
  EXPECT_EQ(verify(v, old_sender.seal(MessageType::kHeartbeat, {}, 100.5).value(), 100.5), Verdict::kExpiredKey);
  EXPECT_EQ(verify(v, new_sender.seal(MessageType::kHeartbeat, {}, 100.5).value(), 100.5), Verdict::kAccepted);
  // Phase 3: key 1 removed from the ring; the windows survive the reload.
  v.setKeys(t::ring({t::keyEntry(2, 22)}, 2));
  EXPECT_EQ(verify(v, old_sender.seal(MessageType::kHeartbeat, {}, 101.0).value(), 101.0), Verdict::kUnknownKey);
  EXPECT_EQ(v.window(2)->highest(), 2u);
  // The signer switches keys without resetting its sequence.
  old_sender.setKeys(t::ring({t::keyEntry(2, 22)}, 2));
  EXPECT_EQ(verify(v, old_sender.seal(MessageType::kHeartbeat, {}, 101.0).value(), 101.0), Verdict::kAccepted);
  // Key id 2 with the wrong bytes is a forgery, not an unknown key.
  Signer mallory(1, t::ring({t::keyEntry(2, 23)}, 2), 1000);
  EXPECT_EQ(verify(v, mallory.seal(MessageType::kHeartbeat, {}, 101.0).value(), 101.0), Verdict::kForged);
}

// 10^5 generated hostile packets (forged, bit-flipped, replayed, stale, truncated, oversize,
// too old, too new, unknown sender / key, malformed) interleaved with a legitimate reordered
// stream from two senders: no hostile packet is accepted, every counter is exact, every
// legitimate packet is accepted exactly once.
TEST(CommVerifierTest, HundredThousandHostilePacketsNoneAccepted) {
  constexpr int kHostile = 100000;
  Verifier v = makeVerifier();
  std::mt19937_64 rng(20250101);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const KeyRing shared = t::ring({t::keyEntry(1, kGoodKey)}, 1);
  std::map<std::uint16_t, Signer> legit;
  legit.emplace(1, Signer(1, shared, 1));
  legit.emplace(2, Signer(2, shared, 5000));

  struct Sent {
    std::vector<std::uint8_t> bytes;
    double stamp;
    std::uint16_t sender;
  };
  std::vector<Sent> pending;   // legitimate packets not yet delivered (reordered delivery)
  std::vector<Sent> accepted;  // delivered legitimate packets (replay material)
  std::set<std::pair<std::uint16_t, std::uint64_t>> accepted_ids;
  std::map<Verdict, std::uint64_t> expected;
  std::uint64_t legit_sent = 0;
  double now = 1000.0;

  auto deliverLegit = [&]() {
    // Deliver a random pending packet (reordering), as long as it is still fresh.
    // (The oldest first once it is half its maximal age old.)
    const std::size_t i = pending.front().stamp < now - 0.5 ? 0 : static_cast<std::size_t>(rng() % pending.size());
    Sent p = std::move(pending[i]);
    pending.erase(pending.begin() + static_cast<long>(i));
    VerifyResult r = v.verify(p.bytes.data(), p.bytes.size(), now);
    ASSERT_EQ(r.verdict, Verdict::kAccepted) << toString(r.verdict);
    ASSERT_TRUE(accepted_ids.insert({r.envelope.sender_id, r.envelope.sequence}).second);
    ++expected[Verdict::kAccepted];
    accepted.push_back(std::move(p));
    if (accepted.size() > 200) accepted.erase(accepted.begin());
  };

  for (int i = 0; i < kHostile; ++i) {
    now += 0.001;
    // Legitimate traffic: about one packet in four, delivered up to ~20 packets late.
    if (rng() % 4 == 0) {
      const std::uint16_t sender = (rng() % 2) ? 1 : 2;
      auto b = legit.at(sender).seal(MessageType::kWorkerState, t::randomBytes(rng, rng() % 64), now);
      ASSERT_TRUE(b);
      pending.push_back({std::move(b.value()), now, sender});
      ++legit_sent;
    }
    while (pending.size() > 20 || (!pending.empty() && rng() % 3 == 0)) deliverLegit();

    // One hostile packet; the verdict it must get is known by construction.
    const std::uint16_t victim = (rng() % 2) ? 1 : 2;
    const std::uint64_t next_seq = legit.at(victim).nextSequence();  // the victim's next number
    const auto payload = t::randomBytes(rng, rng() % 100);
    std::vector<std::uint8_t> b;
    Verdict verdict;
    switch (i % 12) {
      case 0:  // forged with a wrong key, using the victim's next sequence number
        b = seal(victim, next_seq, now, kEvilKey, 1, MessageType::kFormationCommand, payload);
        verdict = Verdict::kForged;
        break;
      case 1: {  // valid packet with one bit flipped in the sequence, payload or tag
        b = seal(victim, next_seq, now, kGoodKey, 1, MessageType::kFormationCommand, payload);
        std::size_t pos;
        do {
          pos = static_cast<std::size_t>(rng() % b.size());
        } while (pos < 8 || (pos >= 16 && pos < kHeaderBytes));
        b[pos] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
        verdict = Verdict::kForged;
        break;
      }
      case 2:  // replay of a delivered legitimate packet (still fresh, within the window)
        if (accepted.empty() || accepted.back().stamp < now - 0.5) {
          b = seal(victim, next_seq, now, kEvilKey);
          verdict = Verdict::kForged;
        } else {
          const Sent& old = accepted[accepted.size() - 1 - static_cast<std::size_t>(rng() % std::min<std::size_t>(accepted.size(), 50))];
          b = old.stamp >= now - 0.9 ? old.bytes : accepted.back().bytes;
          verdict = Verdict::kReplayed;
        }
        break;
      case 3: {  // truncated valid packet
        b = seal(victim, next_seq, now, kGoodKey, 1, MessageType::kHeartbeat, payload);
        b.resize(static_cast<std::size_t>(rng() % b.size()));
        verdict = Verdict::kTruncated;
        break;
      }
      case 4:  // oversize datagram or oversize length field
        if (rng() % 2) {
          b = t::randomBytes(rng, kMaxEnvelopeBytes + 1 + rng() % 1000);
        } else {
          b = seal(victim, next_seq, now);
          b[24] = static_cast<std::uint8_t>(1 + rng() % 255);  // length ≥ 16 MiB
        }
        verdict = Verdict::kOversize;
        break;
      case 5:  // authentic but too old
        b = seal(victim, next_seq, now - 1.0 - 0.001 - unit(rng) * 100.0);
        verdict = Verdict::kTooOld;
        break;
      case 6:  // authentic but from the future
        b = seal(victim, next_seq, now + 0.25 + 0.001 + unit(rng) * 100.0);
        verdict = Verdict::kTooNew;
        break;
      case 7:  // unknown sender, right key
        b = seal(static_cast<std::uint16_t>(10 + rng() % 60000), next_seq, now);
        verdict = Verdict::kUnknownSender;
        break;
      case 8:  // unknown key id
        b = seal(victim, next_seq, now, kGoodKey, static_cast<std::uint8_t>(2 + rng() % 254));
        verdict = Verdict::kUnknownKey;
        break;
      case 9: {  // authentic, sequence far below the window (stale)
        // Undelivered packets keep the window's top up to ~20 below next_seq: margin 1100.
        const std::uint64_t base = victim == 2 ? 5000 : 1;
        if (next_seq > base + 1101) {
          b = seal(victim, base + rng() % (next_seq - 1100 - base), now);
          verdict = Verdict::kStale;
        } else {
          b = seal(victim, next_seq, now - 5.0);
          verdict = Verdict::kTooOld;
        }
        break;
      }
      case 10: {  // bad version / type / magic / flags / trailing bytes / NaN stamp
        b = seal(victim, next_seq, now);
        const int kind = static_cast<int>(rng() % 6);
        if (kind == 0) {
          b[2] = static_cast<std::uint8_t>(3 + rng() % 253);
          verdict = Verdict::kBadVersion;
        } else if (kind == 1) {
          b[3] = static_cast<std::uint8_t>(kMaxMessageType + 1 + rng() % (255 - kMaxMessageType));
          verdict = Verdict::kBadType;
        } else if (kind == 2) {
          b[0] ^= static_cast<std::uint8_t>(1 + rng() % 255);
          verdict = Verdict::kMalformed;
        } else if (kind == 3) {
          b[7] = static_cast<std::uint8_t>(1 + rng() % 255);
          verdict = Verdict::kMalformed;
        } else if (kind == 4) {
          b.push_back(0);
          verdict = Verdict::kMalformed;
        } else {
          b[16] = 0x7F;  // exponent all ones: inf or NaN
          b[17] |= 0xF0;
          verdict = Verdict::kMalformed;
        }
        break;
      }
      default: {  // random garbage not starting with the magic
        b = t::randomBytes(rng, rng() % 200);
        if (!b.empty() && b[0] == kMagic0) b[0] = 0;
        verdict = b.size() < kMinEnvelopeBytes ? Verdict::kTruncated : Verdict::kMalformed;
        break;
      }
    }
    VerifyResult r = v.verify(b.data(), b.size(), now);
    ASSERT_EQ(r.verdict, verdict) << "packet " << i << " case " << i % 12 << ": " << r.detail;
    ++expected[verdict];
  }
  while (!pending.empty()) deliverLegit();

  EXPECT_EQ(v.counters().accepted(), legit_sent);
  EXPECT_EQ(accepted_ids.size(), legit_sent);
  EXPECT_EQ(v.counters().rejected(), static_cast<std::uint64_t>(kHostile));
  for (std::size_t k = 0; k < kVerdictCount; ++k) {
    const Verdict verdict = static_cast<Verdict>(k);
    EXPECT_EQ(v.counters().count(verdict), expected[verdict]) << toString(verdict);
  }
  // Every kind was exercised.
  for (Verdict verdict : {Verdict::kForged, Verdict::kReplayed, Verdict::kTruncated, Verdict::kOversize,
                          Verdict::kTooOld, Verdict::kTooNew, Verdict::kUnknownSender, Verdict::kUnknownKey,
                          Verdict::kStale, Verdict::kBadVersion, Verdict::kBadType, Verdict::kMalformed}) {
    EXPECT_GT(expected[verdict], 1000u) << toString(verdict);
  }
  std::printf("[ figures  ] %d hostile packets, %llu legitimate accepted; forged %llu replayed %llu stale %llu "
              "truncated %llu oversize %llu too_old %llu too_new %llu unknown_sender %llu unknown_key %llu "
              "bad_version %llu bad_type %llu malformed %llu\n",
              kHostile, static_cast<unsigned long long>(legit_sent),
              static_cast<unsigned long long>(expected[Verdict::kForged]),
              static_cast<unsigned long long>(expected[Verdict::kReplayed]),
              static_cast<unsigned long long>(expected[Verdict::kStale]),
              static_cast<unsigned long long>(expected[Verdict::kTruncated]),
              static_cast<unsigned long long>(expected[Verdict::kOversize]),
              static_cast<unsigned long long>(expected[Verdict::kTooOld]),
              static_cast<unsigned long long>(expected[Verdict::kTooNew]),
              static_cast<unsigned long long>(expected[Verdict::kUnknownSender]),
              static_cast<unsigned long long>(expected[Verdict::kUnknownKey]),
              static_cast<unsigned long long>(expected[Verdict::kBadVersion]),
              static_cast<unsigned long long>(expected[Verdict::kBadType]),
              static_cast<unsigned long long>(expected[Verdict::kMalformed]));
}

// One range per setting (issue 34): the LcmBridge nodelet reads max_age_s (and checks
// command_max_age_s) with verifierFields()' range, and validate() refuses exactly what it refuses
// (the nodelet had [0.01, 60], validate() (0, inf): both now [0.01, 60]).
TEST(CommVerifierTest, ValidateAndTheBridgeParametersAgreeOnBoundaries) {
  const gesture_formation::common::Range& range = *verifierFields().rangeOf("max_age_s");
  for (const double age : {0.01, 60.0, 0.005, 60.5, 0.0}) {
    VerifierConfig c = config();
    c.max_age_s = age;
    EXPECT_EQ(c.validate().empty(), range.contains(age)) << age;
    c = config();
    c.max_age_s_by_type[MessageType::kFormationCommand] = age;
    EXPECT_EQ(c.validate().empty(), range.contains(age)) << age;
  }
  EXPECT_TRUE(range.contains(0.01));
  EXPECT_FALSE(range.contains(60.5));
}
