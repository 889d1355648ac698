// lcm_bridge::startLink (a node's link start-up) on memq:// and files in a private temporary
// directory: every problem at once, the boot counter advancing per start, high-water marks restored.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "gesture_formation/comm/sequence_store.hpp"
#include "gesture_formation/lcm_bridge/link_startup.hpp"

using namespace gesture_formation;
using namespace gesture_formation::lcm_bridge;

namespace {

const std::string kHex = "000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f";

class LinkStartupTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/gf_link_startup_XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
    writeFile(dir_ + "/group.key", "1 " + kHex + "\n", 0600);
    config_.link.sender_id = 1;
    config_.link.known_senders = {1, 2};
    config_.lcm_url = "memq://";
    config_.channel_prefix = "GF_";
    config_.key_file = dir_ + "/group.key";
    config_.state_dir = dir_ + "/state";
    config_.sequence_file = config_.state_dir + "/b.boot";
    config_.marks_file = config_.state_dir + "/b.marks";
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  static void writeFile(const std::string& path, const std::string& text, mode_t mode) {
    std::ofstream(path) << text;
    ::chmod(path.c_str(), mode);
  }
  static bool hasKey(const std::vector<common::ConfigError>& problems, const std::string& key) {
    for (const auto& p : problems) {
      if (p.key == key) return true;
    }
    return false;
  }
  std::string dir_;
  LinkStartupConfig config_;
};

double zeroClock() { return 0.0; }

}  // namespace

TEST_F(LinkStartupTest, StartsAndAdvancesTheBootCounterAtEachStart) {
  std::vector<common::ConfigError> problems;
  auto first = startLink(config_, zeroClock, problems);
  ASSERT_TRUE(first) << (problems.empty() ? "" : problems[0].key + ": " + problems[0].message);
  EXPECT_EQ(first->boot, 1u);
  EXPECT_EQ(first->first_sequence, comm::firstSequenceOfBoot(1));
  EXPECT_FALSE(first->per_sender_keys);
  EXPECT_EQ(first->restored_marks, 0u);
  ASSERT_TRUE(first->link && first->transport);
  EXPECT_EQ(first->link->signer().senderId(), 1);
  struct stat st {};
  ASSERT_EQ(::stat(config_.state_dir.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0700u);
  first->link.reset();

  ASSERT_TRUE(comm::saveHighWaterMarks(config_.marks_file, {{2, 77}}));
  auto second = startLink(config_, zeroClock, problems);
  ASSERT_TRUE(second);
  EXPECT_EQ(second->boot, 2u);
  EXPECT_EQ(second->restored_marks, 1u);
  EXPECT_EQ(second->link->verifier().highWaterMarks().at(2), 77u);
  EXPECT_TRUE(problems.empty());
}

TEST_F(LinkStartupTest, ReportsTheSettingsAndTheKeyFileTogetherAndWritesNothing) {
  config_.link.recv_buf_bytes = 100;
  writeFile(config_.key_file, "1 " + kHex + "\n", 0644);  // readable by others
  const auto checked = checkLinkStartup(config_);
  EXPECT_TRUE(hasKey(checked, "recv_buf_bytes"));
  EXPECT_TRUE(hasKey(checked, "key_file"));
  std::vector<common::ConfigError> problems;
  EXPECT_FALSE(startLink(config_, zeroClock, problems));
  EXPECT_TRUE(hasKey(problems, "recv_buf_bytes"));
  EXPECT_TRUE(hasKey(problems, "key_file"));
  struct stat st {};
  EXPECT_NE(::stat(config_.sequence_file.c_str(), &st), 0) << "no boot counter written when refusing";
}

TEST_F(LinkStartupTest, AnEmptyKeyFileAndABadUrlAreNamed) {
  config_.key_file.clear();
  std::vector<common::ConfigError> problems;
  EXPECT_FALSE(startLink(config_, zeroClock, problems));
  ASSERT_TRUE(hasKey(problems, "key_file"));
  config_.key_file = dir_ + "/group.key";
  config_.lcm_url = "nosuchprovider://";
  problems.clear();
  EXPECT_FALSE(startLink(config_, zeroClock, problems));
  EXPECT_TRUE(hasKey(problems, "lcm_url"));
}

TEST_F(LinkStartupTest, ABadStateFileIsNamed) {
  ASSERT_EQ(::mkdir(config_.state_dir.c_str(), 0700), 0);
  writeFile(config_.marks_file, "0 12\n1 x\n", 0600);
  std::vector<common::ConfigError> problems;
  EXPECT_FALSE(startLink(config_, zeroClock, problems));
  EXPECT_TRUE(hasKey(problems, "high_water_file"));
}

TEST(HighWaterMarkSaverTest, SavesOnlyChangedNonEmptyMarks) {
  char tmpl[] = "/tmp/gf_marks_XXXXXX";
  ASSERT_NE(::mkdtemp(tmpl), nullptr);
  const std::string path = std::string(tmpl) + "/m";
  HighWaterMarkSaver saver(path);
  auto r = saver.save({});
  ASSERT_TRUE(r);
  EXPECT_FALSE(r.value());
  r = saver.save({{1, 5}});
  ASSERT_TRUE(r);
  EXPECT_TRUE(r.value());
  r = saver.save({{1, 5}});
  EXPECT_FALSE(r.value());
  EXPECT_EQ(comm::loadHighWaterMarks(path).value().at(1), 5u);
  std::filesystem::remove_all(tmpl);
}
