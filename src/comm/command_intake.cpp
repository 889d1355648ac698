#include "gesture_formation/comm/command_intake.hpp"

#include <utility>

namespace gesture_formation::comm {

std::string CommandIntake::boundName(const std::string& name, std::uint16_t sender) {
  return name + "@" + std::to_string(sender);
}

std::optional<formation::FormationCommand> CommandIntake::accept(std::uint16_t envelope_sender,
                                                                 formation::FormationCommand command) {
  Id id{envelope_sender, command.id.sender, command.id.sequence};
  if (seen_.count(id) != 0) {
    ++copies_dropped_;
    return std::nullopt;
  }
  seen_.insert(id);
  auto& order = order_[envelope_sender];
  order.push_back(std::move(id));
  if (order.size() > kRememberedPerSender) {
    seen_.erase(order.front());
    order.pop_front();
  }
  command.id.sender = boundName(command.id.sender, envelope_sender);
  return command;
}

}  // namespace gesture_formation::comm
