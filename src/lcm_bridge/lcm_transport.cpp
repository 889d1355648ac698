#include "gesture_formation/lcm_bridge/lcm_transport.hpp"

#include <lcm/lcm-cpp.hpp>

#include <exception>

#include "gf_lcm/envelope_t.hpp"

namespace gesture_formation::lcm_bridge {

namespace {

struct ChannelSuffix {
  comm::MessageType type;
  const char* suffix;
};
constexpr ChannelSuffix kChannels[] = {
    {comm::MessageType::kHeartbeat, "HEARTBEAT"},
    {comm::MessageType::kWorkerState, "WORKER_STATE"},
    {comm::MessageType::kPlannedTrajectory, "PLANNED_TRAJECTORY"},
    {comm::MessageType::kFormationParams, "FORMATION_PARAMS"},
    {comm::MessageType::kFormationCommand, "FORMATION_COMMAND"},
    {comm::MessageType::kGestureObservation, "GESTURE_OBSERVATION"},
};

/// LCM's fixed part of gf_lcm::envelope_t: 8-byte fingerprint + int32 length.
constexpr std::size_t kLcmOverheadBytes = 12;
/// Undispatched messages LCM keeps for our subscription (LCM's default: 30).
constexpr int kQueueCapacity = 2000;

}  // namespace

std::string channelName(comm::MessageType type, const std::string& prefix) {
  for (const ChannelSuffix& c : kChannels) {
    if (c.type == type) return prefix + c.suffix;
  }
  return prefix + "UNKNOWN";
}

std::optional<comm::MessageType> channelType(const std::string& channel, const std::string& prefix) {
  if (channel.compare(0, prefix.size(), prefix) != 0) return std::nullopt;
  const std::string suffix = channel.substr(prefix.size());
  for (const ChannelSuffix& c : kChannels) {
    if (suffix == c.suffix) return c.type;
  }
  return std::nullopt;
}

std::vector<std::uint8_t> encodeLcmEnvelope(const std::vector<std::uint8_t>& sealed) {
  if (sealed.size() > comm::kMaxEnvelopeBytes) return {};
  gf_lcm::envelope_t msg;
  msg.num_bytes = static_cast<std::int32_t>(sealed.size());
  msg.bytes.assign(sealed.begin(), sealed.end());
  std::vector<std::uint8_t> out(static_cast<std::size_t>(msg.getEncodedSize()));
  if (msg.encode(out.data(), 0, static_cast<int>(out.size())) != static_cast<int>(out.size())) return {};
  return out;
}

bool decodeLcmEnvelope(const void* data, std::size_t size, std::vector<std::uint8_t>& sealed) {
  if (data == nullptr || size < kLcmOverheadBytes || size > kLcmOverheadBytes + comm::kMaxEnvelopeBytes) return false;
  const auto* p = static_cast<const std::uint8_t*>(data);
  // LCM integers are big-endian; the length must describe exactly the rest of the buffer.
  const std::uint32_t length = (std::uint32_t{p[8]} << 24) | (std::uint32_t{p[9]} << 16) |
                               (std::uint32_t{p[10]} << 8) | std::uint32_t{p[11]};
  if (length > comm::kMaxEnvelopeBytes || kLcmOverheadBytes + length != size) return false;
  gf_lcm::envelope_t msg;
  try {
    if (msg.decode(data, 0, static_cast<int>(size)) != static_cast<int>(size)) return false;
  } catch (const std::exception&) {
    return false;
  }
  if (msg.num_bytes < 0 || static_cast<std::size_t>(msg.num_bytes) != msg.bytes.size()) return false;
  sealed = std::move(msg.bytes);
  return true;
}

struct LcmTransport::Impl {
  explicit Impl(const std::string& url) : lcm(url) {}
  lcm::LCM lcm;
  LcmTransport* owner = nullptr;

  void onMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    owner->counters_.received++;
    const auto type = channelType(channel, owner->prefix_);
    std::vector<std::uint8_t> sealed;
    if (!type || rbuf == nullptr ||
        !decodeLcmEnvelope(rbuf->data, static_cast<std::size_t>(rbuf->data_size), sealed)) {
      owner->counters_.undecodable++;
      return;
    }
    if (owner->handler_) owner->handler_(*type, sealed);
  }
};

common::Result<std::unique_ptr<LcmTransport>> LcmTransport::create(const std::string& url,
                                                                    const std::string& channel_prefix) {
  using R = common::Result<std::unique_ptr<LcmTransport>>;
  if (channel_prefix.empty()) return R::fail("LCM channel prefix must not be empty");
  auto impl = std::make_unique<Impl>(url);
  if (!impl->lcm.good()) return R::fail("cannot open LCM with URL '" + url + "'");
  std::unique_ptr<LcmTransport> t(new LcmTransport(std::move(impl), channel_prefix));
  t->impl_->owner = t.get();
  // One regex subscription for our channels (LCM anchors it with ^...$).
  lcm::Subscription* sub = t->impl_->lcm.subscribe(
      channel_prefix + "(HEARTBEAT|WORKER_STATE|PLANNED_TRAJECTORY|FORMATION_PARAMS|FORMATION_COMMAND|GESTURE_OBSERVATION)",
      &Impl::onMessage, t->impl_.get());
  // LCM's default holds 30 undispatched messages and drops the rest unseen: room for a burst.
  if (sub != nullptr) sub->setQueueCapacity(kQueueCapacity);
  return R::ok(std::move(t));
}

LcmTransport::LcmTransport(std::unique_ptr<Impl> impl, std::string prefix)
    : impl_(std::move(impl)), prefix_(std::move(prefix)) {}

LcmTransport::~LcmTransport() = default;

bool LcmTransport::publish(comm::MessageType type, const std::vector<std::uint8_t>& sealed) {
  const std::vector<std::uint8_t> encoded = encodeLcmEnvelope(sealed);
  if (encoded.empty() ||
      impl_->lcm.publish(channelName(type, prefix_), encoded.data(), static_cast<unsigned int>(encoded.size())) != 0) {
    counters_.publish_failed++;
    return false;
  }
  counters_.published++;
  return true;
}

void LcmTransport::setHandler(Handler handler) { handler_ = std::move(handler); }

int LcmTransport::handle(int timeout_ms) { return impl_->lcm.handleTimeout(timeout_ms); }

int LcmTransport::drain(int max_messages) {
  int n = 0;
  while (n < max_messages && impl_->lcm.handleTimeout(0) > 0) ++n;
  return n;
}

SecureLink::SecureLink(LcmTransport& transport, comm::Signer signer, comm::Verifier verifier, Clock clock)
    : transport_(transport), signer_(std::move(signer)), verifier_(std::move(verifier)), clock_(std::move(clock)) {
  transport_.setHandler(
      [this](comm::MessageType type, const std::vector<std::uint8_t>& sealed) { onSealed(type, sealed); });
}

common::Result<std::uint64_t> SecureLink::publishPayload(comm::MessageType type, const std::vector<std::uint8_t>& payload) {
  const std::uint64_t sequence = signer_.nextSequence();
  auto sealed = signer_.seal(type, payload, clock_());
  if (!sealed) return common::Result<std::uint64_t>::fail(sealed.reason());
  if (!transport_.publish(type, sealed.value())) {
    return common::Result<std::uint64_t>::fail("LCM publish failed on channel " + channelName(type, transport_.prefix()));
  }
  return common::Result<std::uint64_t>::ok(sequence);
}

void SecureLink::onSealed(comm::MessageType channel_type, const std::vector<std::uint8_t>& sealed) {
  // A well-formed envelope's type must name the channel it came on (malformed ones go on to
  // the verifier, which counts them). Checked before
  // verification, so a cross-channel copy changes no replay window; the tag covers the type,
  // so an attacker cannot make an envelope fit another channel.
  comm::EnvelopeView view;
  if (comm::parseEnvelope(sealed.data(), sealed.size(), view) == comm::EnvelopeError::kNone &&
      view.type != channel_type) {
    ++channel_mismatch_;
    return;
  }
  comm::VerifyResult r = verifier_.verify(sealed.data(), sealed.size(), clock_());
  if (r.accepted()) {
    if (handler_) handler_(r.envelope);
  } else if (r.verdict != comm::Verdict::kOwnMessage && reject_handler_) {
    comm::EnvelopeView claimed;
    const bool parsed = comm::parseEnvelope(sealed.data(), sealed.size(), claimed) == comm::EnvelopeError::kNone;
    reject_handler_(r, parsed ? std::optional<std::uint16_t>(claimed.sender_id) : std::nullopt);
  }
}

}  // namespace gesture_formation::lcm_bridge
