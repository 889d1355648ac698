#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "gesture_formation/comm/key_ring.hpp"

using namespace gesture_formation::comm;

namespace {

const std::string kHexA = "000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f";
const std::string kHexB = "FFEEDDCCBBAA99887766554433221100ffeeddccbbaa99887766554433221100";

/// A temporary key file, removed at the end of the test.
class KeyFile {
 public:
  KeyFile(const std::string& text, mode_t mode) {
    char tmpl[] = "/tmp/gf_test_key_XXXXXX";
    const int fd = ::mkstemp(tmpl);
    path_ = tmpl;
    if (fd >= 0) {
      const ssize_t n = ::write(fd, text.data(), text.size());
      (void)n;
      ::close(fd);
    }
    ::chmod(path_.c_str(), mode);
  }
  ~KeyFile() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace

TEST(CommKeyRingTest, LoadsAnOwnerOnlyFile) {
  KeyFile f("# test keys\n1 " + kHexA + "\n", 0600);
  auto ring = loadKeyFile(f.path());
  ASSERT_TRUE(ring) << ring.reason();
  EXPECT_EQ(ring->activeId(), 1);
  EXPECT_EQ(ring->active().key.data()[0], 0x00);
  EXPECT_EQ(ring->active().key.data()[31], 0x1f);
  KeyFile ro("1 " + kHexA + "\n", 0400);
  EXPECT_TRUE(loadKeyFile(ro.path()));
}

TEST(CommKeyRingTest, RefusesFilesOthersCanAccess) {
  for (mode_t mode : {0644, 0640, 0604, 0660, 0602, 0610, 0601}) {
    KeyFile f("1 " + kHexA + "\n", mode);
    auto ring = loadKeyFile(f.path());
    ASSERT_FALSE(ring) << std::oct << mode;
    EXPECT_NE(ring.reason().find(f.path()), std::string::npos) << ring.reason();
    EXPECT_NE(ring.reason().find("group or others"), std::string::npos) << ring.reason();
    EXPECT_NE(ring.reason().find("chmod 600"), std::string::npos) << ring.reason();
  }
}

TEST(CommKeyRingTest, MissingFileAndDirectoryAreNamed) {
  auto missing = loadKeyFile("/nonexistent/gf/key");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.reason(), "key file '/nonexistent/gf/key': does not exist");
  auto dir = loadKeyFile("/tmp");
  ASSERT_FALSE(dir);
  EXPECT_NE(dir.reason().find("not a regular file"), std::string::npos) << dir.reason();
  EXPECT_FALSE(loadKeyFile(""));
}

TEST(CommKeyRingTest, WrongLengthAndBadDigitsNameLineAndKeyButNotTheKey) {
  KeyFile short_key("1 " + kHexA.substr(0, 62) + "\n", 0600);
  auto r = loadKeyFile(short_key.path());
  ASSERT_FALSE(r);
  EXPECT_EQ(r.reason(), short_key.path() + ":1: key 1 has 62 hex digits, expected 64 (32 bytes)");
  KeyFile long_key("\n3 " + kHexA + "00\n", 0600);
  r = loadKeyFile(long_key.path());
  ASSERT_FALSE(r);
  EXPECT_NE(r.reason().find(":2: key 3 has 66 hex digits"), std::string::npos) << r.reason();
  std::string bad = kHexA;
  bad[10] = 'g';
  KeyFile bad_digit("1 " + bad + "\n", 0600);
  r = loadKeyFile(bad_digit.path());
  ASSERT_FALSE(r);
  EXPECT_NE(r.reason().find("non-hex"), std::string::npos);
  EXPECT_EQ(r.reason().find(kHexA.substr(0, 10)), std::string::npos) << "key material echoed";
}

TEST(CommKeyRingTest, RefusesOversizeFiles) {
  KeyFile big(std::string(kMaxKeyFileBytes + 1, '#'), 0600);
  auto r = loadKeyFile(big.path());
  ASSERT_FALSE(r);
  EXPECT_NE(r.reason().find("larger than " + std::to_string(kMaxKeyFileBytes)), std::string::npos) << r.reason();
}

TEST(CommKeyRingTest, ParsesARotationFile) {
  auto r = parseKeyFileText("1 " + kHexA + " accept_until_s=1700000000.5\n2 " + kHexB + " active\n", "keys");
  ASSERT_TRUE(r) << r.reason();
  EXPECT_EQ(r->activeId(), 2);
  ASSERT_NE(r->find(1), nullptr);
  EXPECT_DOUBLE_EQ(r->find(1)->accept_until_s, 1700000000.5);
  EXPECT_TRUE(std::isinf(r->find(2)->accept_until_s));
  EXPECT_EQ(r->find(3), nullptr);
}

TEST(CommKeyRingTest, RotationFileErrors) {
  struct Case {
    std::string text;
    std::string expected;
  };
  const Case cases[] = {
      {"", "keys: no keys"},
      {"# only a comment\n", "keys: no keys"},
      {"1 " + kHexA + "\n2 " + kHexB + "\n", "keys: several keys but none marked 'active'"},
      {"1 " + kHexA + " active\n2 " + kHexB + " active\n", "keys: more than one key marked 'active'"},
      {"1 " + kHexA + " active\n1 " + kHexB + "\n", "keys: duplicate key id 1"},
      {"1 " + kHexA + " active accept_until_s=5\n", "keys: active key 1 must not have accept_until_s (it is being retired)"},
      {"1 " + kHexA + " accept_until_s=nan\n", "keys:1: key 1: accept_until_s must be a finite number of seconds"},
      {"256 " + kHexA + "\n", "keys:1: key id must be a decimal number 0..255"},
      {"1 " + kHexA + " primary\n", "keys:1: unknown option in word 3 (expected 'active', 'signing', 'verifying', 'sender=<id>' or 'accept_until_s=<s>')"},
      // A key pasted twice on one line: the error must not echo it.
      {"1 " + kHexA + " " + kHexB + "\n", "keys:1: unknown option in word 3 (expected 'active', 'signing', 'verifying', 'sender=<id>' or 'accept_until_s=<s>')"},
      {"1\n", "keys:1: expected '<key_id> <64 hex digits> [signing|verifying sender=<id>] [active] [accept_until_s=<s>]'"},
      {"1 " + kHexA + "\n2 " + kHexA + "\n3 " + kHexA + "\n4 " + kHexA + "\n5 " + kHexA + "\n", "keys:5: more than 4 keys"},
  };
  for (const Case& c : cases) {
    auto r = parseKeyFileText(c.text, "keys");
    ASSERT_FALSE(r) << c.text;
    EXPECT_EQ(r.reason(), c.expected);
  }
}

TEST(CommKeyRingTest, CreateValidates) {
  std::vector<KeyEntry> none;
  EXPECT_FALSE(KeyRing::create(none, 0));
  KeyEntry a;
  a.id = 1;
  EXPECT_FALSE(KeyRing::create({a}, 2));
  EXPECT_TRUE(KeyRing::create({a}, 1));
}
