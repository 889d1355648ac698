#pragma once
/// \file
/// \brief What an encoder says of a time that is not a wire time (comm::isWireTime, envelope.hpp):
/// the one wording of the envelope's, the payloads' and the map updates' refusals.

#include <string>

namespace gesture_formation::comm {

/// \brief "FIELD must be a time in [0, 4e9) s, got T"; empty when t_s is a wire time.
std::string wireTimeProblem(double t_s, const std::string& field);

}  // namespace gesture_formation::comm
