// comm::CommandIntake (docs/security.md §2): the first copy of a command is forwarded with its
// name bound to the envelope's sender, repeats are dropped, and ids are kept per sender.
#include <gtest/gtest.h>

#include "gesture_formation/comm/command_intake.hpp"

using gesture_formation::comm::CommandIntake;
using gesture_formation::formation::FormationCommand;

namespace {

FormationCommand command(const std::string& name, std::uint64_t sequence) {
  FormationCommand c;
  c.id.sender = name;
  c.id.sequence = sequence;
  return c;
}

}  // namespace

TEST(CommandIntakeTest, FirstCopyForwardedWithTheNameBoundToTheEnvelopeSender) {
  CommandIntake intake;
  const auto first = intake.accept(100, command("gcs", 7));
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->id.sender, "gcs@100");
  EXPECT_EQ(first->id.sequence, 7u);
  EXPECT_FALSE(intake.accept(100, command("gcs", 7)).has_value());
  EXPECT_FALSE(intake.accept(100, command("gcs", 7)).has_value());
  EXPECT_EQ(intake.copiesDropped(), 2u);
}

// Another key holder writing the same name and sequence neither shadows the command nor is
// mistaken for it downstream: its copy is forwarded under its own bound name.
TEST(CommandIntakeTest, TheSameNameFromAnotherSenderIsAnotherCommand) {
  CommandIntake intake;
  ASSERT_TRUE(intake.accept(100, command("gcs", 1)).has_value());
  const auto other = intake.accept(101, command("gcs", 1));
  ASSERT_TRUE(other.has_value());
  EXPECT_EQ(other->id.sender, "gcs@101");
  EXPECT_NE(other->id.sender, CommandIntake::boundName("gcs", 100));
  EXPECT_EQ(intake.copiesDropped(), 0u);
}

// One sender's flood of distinct ids evicts only its own remembered ids.
TEST(CommandIntakeTest, ASenderCannotFlushAnotherSendersIds) {
  CommandIntake intake;
  ASSERT_TRUE(intake.accept(100, command("gcs", 1)).has_value());
  for (std::uint64_t s = 0; s < 10 * CommandIntake::kRememberedPerSender; ++s) {
    ASSERT_TRUE(intake.accept(101, command("gcs", 1000 + s)).has_value());
  }
  EXPECT_FALSE(intake.accept(100, command("gcs", 1)).has_value()) << "sender 100's id was forgotten";
  // Its own oldest ids are forgotten (bounded memory): the first of sender 101's is new again.
  EXPECT_TRUE(intake.accept(101, command("gcs", 1000)).has_value());
}
