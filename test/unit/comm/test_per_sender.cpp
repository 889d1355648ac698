// Per-sender keys (envelope version 2, Ed25519; docs/security.md §5): a message verifies only
// with its claimed sender's key; holding one node's signing key does not let it speak for another.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "comm_test_util.hpp"
#include "gesture_formation/comm/ed25519.hpp"
#include "gesture_formation/comm/signer.hpp"
#include "gesture_formation/comm/verifier.hpp"

using namespace gesture_formation::comm;
namespace t = gesture_formation::comm::testing;

namespace {

// Seed fills of the fleet: leader 0, followers 1 and 2, ground station 100.
constexpr std::uint8_t kLeaderSeed = 40, kFollower1Seed = 41, kFollower2Seed = 42, kGroundSeed = 43;

std::vector<std::uint8_t> hex(const std::string& h) {
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i + 1 < h.size(); i += 2) out.push_back(static_cast<std::uint8_t>(std::stoul(h.substr(i, 2), nullptr, 16)));
  return out;
}

/// Follower 2's receiver: knows the leader (0), follower 1 and the ground station (100).
Verifier follower2Verifier() {
  VerifierConfig c;
  c.known_senders = {0, 1, 100};
  c.own_sender_id = 2;
  auto v = Verifier::create(c, t::perSenderRing(2, kFollower2Seed, {{0, kLeaderSeed}, {1, kFollower1Seed}, {100, kGroundSeed}}));
  EXPECT_TRUE(v) << v.reason();
  return std::move(v.value());
}

std::vector<std::uint8_t> sealAs(std::uint16_t claimed_sender, std::uint8_t seed_fill, std::uint64_t sequence,
                                 double stamp_s, std::uint8_t key_id = 1) {
  Envelope e;
  e.type = MessageType::kFormationCommand;
  e.sender_id = claimed_sender;
  e.key_id = key_id;
  e.sequence = sequence;
  e.stamp_s = stamp_s;
  e.payload = {1, 2, 3};
  const auto seed = t::keyBytes(seed_fill);
  auto b = sealEnvelopeEd25519(e, seed.data());
  EXPECT_TRUE(b) << b.reason();
  return b.value();
}

}  // namespace

// RFC 8032 §7.1, test 1 (an independent reference for OpenSSL's Ed25519 as we call it).
TEST(CommEd25519Test, MatchesRfc8032TestVector1) {
  const auto seed = hex("9d61b19deffd5a60ba844af492ec2cc44449c5697b326919703bac031cae7f60");
  const auto expected_pub = hex("d75a980182b10ab7d54bfed3c964073a0ee172f3daa62325af021a68f707511a");
  const auto expected_sig = hex(
      "e5564300c360ac729086e2cc806e828a84877f1eb8e5d974d873e065224901555fb8821590a33bacc61e39701cf9b46bd25bf5f0595bbe24655141438e7a100b");
  PublicKey pub{};
  ASSERT_TRUE(ed25519PublicFromSeed(seed.data(), pub));
  EXPECT_EQ(std::vector<std::uint8_t>(pub.begin(), pub.end()), expected_pub);
  Signature sig{};
  ASSERT_TRUE(ed25519Sign(seed.data(), nullptr, 0, sig));
  EXPECT_EQ(std::vector<std::uint8_t>(sig.begin(), sig.end()), expected_sig);
  EXPECT_TRUE(ed25519Verify(pub, nullptr, 0, sig.data()));
  sig[10] ^= 1;
  EXPECT_FALSE(ed25519Verify(pub, nullptr, 0, sig.data()));
}

TEST(CommPerSenderTest, SignerSealsVersion2AndThePeerAccepts) {
  Signer leader(0, t::perSenderRing(0, kLeaderSeed, {{2, kFollower2Seed}}), 1000);
  auto b = leader.seal(MessageType::kHeartbeat, {0, 0, 0, 0, 0, 0, 0, 0}, 50.0);
  ASSERT_TRUE(b) << b.reason();
  EXPECT_EQ((*b)[2], kEnvelopeVersionEd25519);
  EXPECT_EQ(b->size(), kHeaderBytes + 8 + kEd25519SignatureBytes);
  Verifier v = follower2Verifier();
  const VerifyResult r = v.verify(b->data(), b->size(), 50.1);
  ASSERT_TRUE(r.accepted()) << r.detail;
  EXPECT_EQ(r.envelope.sender_id, 0);
  EXPECT_EQ(r.envelope.version, kEnvelopeVersionEd25519);
}

TEST(CommPerSenderTest, OneFollowersKeyCannotSpeakForAnotherSender) {
  Verifier v = follower2Verifier();
  // Follower 1's own key, claiming to be the leader, follower 1 itself, the ground station and
  // an unknown id: only its own claim verifies.
  for (const std::uint16_t claimed : {0, 100}) {
    const auto b = sealAs(claimed, kFollower1Seed, 5000, 10.0);
    const VerifyResult r = v.verify(b.data(), b.size(), 10.0);
    EXPECT_EQ(r.verdict, Verdict::kForged) << "claimed sender " << claimed << ": " << r.detail;
  }
  const auto unknown = sealAs(7, kFollower1Seed, 5000, 10.0);
  EXPECT_EQ(v.verify(unknown.data(), unknown.size(), 10.0).verdict, Verdict::kUnknownSender);
  // The forgeries changed no window: the leader's real number 1 is still accepted afterwards.
  const auto own = sealAs(1, kFollower1Seed, 5000, 10.0);
  EXPECT_TRUE(v.verify(own.data(), own.size(), 10.0).accepted());
  const auto real = sealAs(0, kLeaderSeed, 1, 10.0);
  EXPECT_TRUE(v.verify(real.data(), real.size(), 10.0).accepted());
  EXPECT_EQ(v.counters().count(Verdict::kForged), 2u);
}

TEST(CommPerSenderTest, GroupKeyEnvelopesAreRefusedByAPerSenderReceiverAndViceVersa) {
  Verifier per_sender = follower2Verifier();
  Signer group(0, t::ring({t::keyEntry(1, 10)}, 1), 1);
  auto v1 = group.seal(MessageType::kHeartbeat, {0, 0, 0, 0, 0, 0, 0, 0}, 1.0);
  ASSERT_TRUE(v1);
  EXPECT_EQ(per_sender.verify(v1->data(), v1->size(), 1.0).verdict, Verdict::kUnknownKey);

  VerifierConfig c;
  c.known_senders = {0};
  auto group_verifier = Verifier::create(c, t::ring({t::keyEntry(1, 10)}, 1));
  ASSERT_TRUE(group_verifier);
  const auto v2 = sealAs(0, kLeaderSeed, 1, 1.0);
  EXPECT_EQ(group_verifier->verify(v2.data(), v2.size(), 1.0).verdict, Verdict::kUnknownKey);
}

TEST(CommPerSenderTest, RotationOfOneSendersKeyByKeyId) {
  // Receiver holds the leader's key 1 (accepted until t = 100) and key 2.
  std::vector<KeyEntry> keys{t::signingEntry(1, 2, kFollower2Seed),
                             verifyingKeyOf(t::signingEntry(1, 0, kLeaderSeed), 100.0),
                             verifyingKeyOf(t::signingEntry(2, 0, 77))};
  VerifierConfig c;
  c.known_senders = {0};
  c.own_sender_id = 2;
  auto v = Verifier::create(c, t::ring(std::move(keys), 1));
  ASSERT_TRUE(v) << v.reason();
  const auto old_key = sealAs(0, kLeaderSeed, 1, 99.5, 1);
  EXPECT_TRUE(v->verify(old_key.data(), old_key.size(), 99.5).accepted());
  const auto new_key = sealAs(0, 77, 2, 99.6, 2);
  EXPECT_TRUE(v->verify(new_key.data(), new_key.size(), 99.6).accepted());
  const auto late_old = sealAs(0, kLeaderSeed, 3, 100.5, 1);
  EXPECT_EQ(v->verify(late_old.data(), late_old.size(), 100.5).verdict, Verdict::kExpiredKey);
  // Key 2 of the leader signed with the old seed: forged; key 3: unknown.
  const auto wrong = sealAs(0, kLeaderSeed, 4, 100.5, 2);
  EXPECT_EQ(v->verify(wrong.data(), wrong.size(), 100.5).verdict, Verdict::kForged);
  const auto unknown = sealAs(0, 77, 5, 100.5, 3);
  EXPECT_EQ(v->verify(unknown.data(), unknown.size(), 100.5).verdict, Verdict::kUnknownKey);
}

TEST(CommPerSenderTest, ConfigurationMistakesAreRefused) {
  // A known sender without a verifying key.
  VerifierConfig c;
  c.known_senders = {0, 5};
  auto v = Verifier::create(c, t::perSenderRing(2, kFollower2Seed, {{0, kLeaderSeed}}));
  ASSERT_FALSE(v);
  EXPECT_NE(v.reason().find("known sender 5 has no verifying key"), std::string::npos) << v.reason();
  // The active signing key of another sender: the signer refuses instead of sealing.
  Signer wrong(3, t::perSenderRing(2, kFollower2Seed, {{0, kLeaderSeed}}), 1);
  auto b = wrong.seal(MessageType::kHeartbeat, {}, 1.0);
  ASSERT_FALSE(b);
  EXPECT_NE(b.reason().find("belongs to sender 2"), std::string::npos) << b.reason();
  EXPECT_EQ(wrong.nextSequence(), 1u);
  // Group keys never mix with per-sender keys; signing keys of two senders are refused.
  auto mixed = KeyRing::create({t::signingEntry(1, 2, 1), t::keyEntry(2, 5)}, 1);
  ASSERT_FALSE(mixed);
  EXPECT_NE(mixed.reason().find("mixed with per-sender keys"), std::string::npos) << mixed.reason();
  auto two = KeyRing::create({t::signingEntry(1, 2, 1), t::signingEntry(2, 3, 1)}, 1);
  ASSERT_FALSE(two);
  EXPECT_NE(two.reason().find("signing keys of two senders"), std::string::npos) << two.reason();
  auto none = KeyRing::create({verifyingKeyOf(t::signingEntry(1, 2, 1))}, 1);
  ASSERT_FALSE(none);
  EXPECT_NE(none.reason().find("no signing key"), std::string::npos) << none.reason();
}

TEST(CommPerSenderTest, KeyFileWithSigningAndVerifyingLines) {
  const std::string a(64, 'a'), b(64, 'b'), c(64, 'c');
  auto ring = parseKeyFileText("# follower 2\n1 " + a + " signing sender=2 active\n1 " + b +
                                   " verifying sender=0\n2 " + c + " verifying sender=0 accept_until_s=50\n",
                               "keys");
  ASSERT_TRUE(ring) << ring.reason();
  EXPECT_TRUE(ring->perSender());
  EXPECT_EQ(ring->active().sender_id, 2);
  EXPECT_EQ(ring->active().kind, KeyKind::kSigning);
  ASSERT_NE(ring->findVerifying(0, 1), nullptr);
  EXPECT_EQ(ring->findVerifying(0, 1)->public_key[0], 0xbb);
  ASSERT_NE(ring->findVerifying(0, 2), nullptr);
  EXPECT_EQ(ring->findVerifying(0, 2)->accept_until_s, 50.0);
  EXPECT_EQ(ring->findVerifying(2, 1), nullptr);
  EXPECT_EQ(ring->find(1), &ring->active());

  struct Case {
    std::string text, expected;
  };
  const std::vector<Case> cases = {
      {"1 " + a + " signing\n", "keys:1: key 1: 'sender=<id>' goes with 'signing' or 'verifying', and they need it"},
      {"1 " + a + " sender=3\n", "keys:1: key 1: 'sender=<id>' goes with 'signing' or 'verifying', and they need it"},
      {"1 " + a + " signing sender=70000\n", "keys:1: key 1: sender must be a decimal id 0..65535"},
      {"1 " + a + " signing sender=-1\n", "keys:1: key 1: sender must be a decimal id 0..65535"},
      {"1 " + a + " signing verifying sender=1\n", "keys:1: key 1: 'signing' or 'verifying' given twice"},
      {"1 " + a + " signing sender=1\n1 " + b + " verifying sender=0 active\n",
       "keys:2: key 1: a verifying key cannot be 'active' (a node signs with its own signing key)"},
      {"1 " + a + " verifying sender=0\n", "keys: no signing key (a 'signing sender=<id>' line for this node)"},
      {"1 " + a + " signing sender=1\n2 " + b + " active\n",
       "keys: group key 2 mixed with per-sender keys (it would let any holder speak for every sender)"},
      {"1 " + a + " signing sender=1 accept_until_s=5\n",
       "keys: signing key 1 of sender 1: accept_until_s applies to verifying keys only"},
      {"1 " + a + " signing sender=1\n1 " + b + " verifying sender=0\n1 " + c + " verifying sender=0\n",
       "keys: duplicate verifying key 1 of sender 0"},
  };
  for (const Case& k : cases) {
    auto r = parseKeyFileText(k.text, "keys");
    ASSERT_FALSE(r) << k.text;
    EXPECT_EQ(r.reason(), k.expected);
    EXPECT_EQ(r.reason().find(a), std::string::npos);
  }
}
