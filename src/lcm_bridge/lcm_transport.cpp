#include "gesture_formation/lcm_bridge/lcm_transport.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
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
    {comm::MessageType::kAbortCommand, "ABORT_COMMAND"},
    {comm::MessageType::kCommandAck, "COMMAND_ACK"},
    {comm::MessageType::kAssistance, "ASSISTANCE"},
    {comm::MessageType::kLeadership, "LEADERSHIP"},
    {comm::MessageType::kMapUpdate, "MAP_UPDATE"},
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

bool parseLcmDatagram(const std::uint8_t* data, std::size_t size, LcmDatagram& out) {
  constexpr std::uint8_t kMagic[4] = {'L', 'C', '0', '2'};
  constexpr std::size_t kHeader = 8;          // magic + sequence number
  constexpr std::size_t kMaxChannel = 63;     // LCM's limit on a channel name
  if (data == nullptr || size <= kHeader || std::memcmp(data, kMagic, 4) != 0) return false;
  const std::size_t room = std::min(size - kHeader, kMaxChannel + 1);
  const auto* name = data + kHeader;
  const auto* end = static_cast<const std::uint8_t*>(std::memchr(name, 0, room));
  if (end == nullptr) return false;
  out.channel.assign(reinterpret_cast<const char*>(name), static_cast<std::size_t>(end - name));
  out.data = end + 1;
  out.size = size - static_cast<std::size_t>(out.data - data);
  return true;
}

namespace {

/// group, port and recv_buf_size of a udpm:// URL ("udpm://239.255.76.67:7667?ttl=0&recv_buf_size=N").
struct UdpmAddress {
  in_addr group{};
  std::uint16_t port = 0;
  int recv_buf_bytes = 0;
};

std::optional<UdpmAddress> parseUdpm(const std::string& url) {
  const std::string scheme = "udpm://";
  if (url.rfind(scheme, 0) != 0) return std::nullopt;
  std::string rest = url.substr(scheme.size());
  std::string query;
  if (const auto q = rest.find('?'); q != std::string::npos) {
    query = rest.substr(q + 1);
    rest = rest.substr(0, q);
  }
  UdpmAddress a;
  const auto colon = rest.find(':');
  const std::string host = colon == std::string::npos ? rest : rest.substr(0, colon);
  const std::string port = colon == std::string::npos ? "7667" : rest.substr(colon + 1);
  if (inet_pton(AF_INET, (host.empty() ? "239.255.76.67" : host).c_str(), &a.group) != 1) return std::nullopt;
  try {
    const int p = std::stoi(port);
    if (p <= 0 || p > 65535) return std::nullopt;
    a.port = static_cast<std::uint16_t>(p);
    const std::string key = "recv_buf_size=";
    if (const auto k = query.find(key); k != std::string::npos) a.recv_buf_bytes = std::stoi(query.substr(k + key.size()));
  } catch (const std::exception&) {
    return std::nullopt;
  }
  return a;
}

/// A non-blocking UDP socket joined to the group (as LCM's own receive socket would be).
common::Result<int> openMulticastSocket(const UdpmAddress& a) {
  using R = common::Result<int>;
  const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) return R::fail(std::string("socket: ") + std::strerror(errno));
  const int one = 1;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_ANY);
  addr.sin_port = htons(a.port);
  ip_mreq mreq{};
  mreq.imr_multiaddr = a.group;
  mreq.imr_interface.s_addr = htonl(INADDR_ANY);
  std::string failed;
  if (setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) < 0) failed = "SO_REUSEADDR";
  else if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) failed = "bind";
  else if (setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) < 0) failed = "IP_ADD_MEMBERSHIP";
  if (!failed.empty()) {
    const std::string why = failed + ": " + std::strerror(errno);
    close(fd);
    return R::fail(why);
  }
  // The kernel caps the buffer at net.core.rmem_max (docs/security.md: floods).
  if (a.recv_buf_bytes > 0) (void)setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &a.recv_buf_bytes, sizeof a.recv_buf_bytes);
  return R::ok(fd);
}

constexpr std::size_t kBatch = 32;             ///< datagrams per recvmmsg (32 x 64 KiB of buffer)
constexpr std::size_t kDatagramBytes = 65536;  ///< the largest UDP datagram

}  // namespace

struct LcmTransport::Impl {
  explicit Impl(const std::string& url) : lcm(url) {}
  ~Impl() {
    if (fd >= 0) close(fd);
  }
  lcm::LCM lcm;
  LcmTransport* owner = nullptr;
  int fd = -1;  ///< our own multicast socket (udpm://), else -1: LCM receives
  std::vector<std::uint8_t> buffers;  ///< kBatch datagrams
  std::array<mmsghdr, kBatch> headers{};
  std::array<iovec, kBatch> iov{};

  void dispatch(const std::string& channel, const std::uint8_t* data, std::size_t size) {
    owner->counters_.received++;
    const auto type = channelType(channel, owner->prefix_);
    std::vector<std::uint8_t> sealed;
    if (!type || !decodeLcmEnvelope(data, size, sealed)) {
      owner->counters_.undecodable++;
      return;
    }
    if (owner->handler_) owner->handler_(*type, sealed);
  }

  void onMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    if (rbuf == nullptr) return dispatch(channel, nullptr, 0);
    dispatch(channel, static_cast<const std::uint8_t*>(rbuf->data), static_cast<std::size_t>(rbuf->data_size));
  }

  /// Reads up to `max` datagrams now (non-blocking); returns how many were read.
  int receive(int max) {
    if (buffers.empty()) buffers.resize(kBatch * kDatagramBytes);
    const unsigned int n = static_cast<unsigned int>(std::min<std::size_t>(kBatch, static_cast<std::size_t>(max)));
    for (unsigned int i = 0; i < n; ++i) {
      iov[i] = iovec{buffers.data() + i * kDatagramBytes, kDatagramBytes};
      headers[i] = mmsghdr{};
      headers[i].msg_hdr.msg_iov = &iov[i];
      headers[i].msg_hdr.msg_iovlen = 1;
    }
    const int got = recvmmsg(fd, headers.data(), n, MSG_DONTWAIT, nullptr);
    if (got <= 0) return 0;
    LcmDatagram d;
    for (int i = 0; i < got; ++i) {
      const auto* bytes = buffers.data() + static_cast<std::size_t>(i) * kDatagramBytes;
      if (!parseLcmDatagram(bytes, headers[static_cast<std::size_t>(i)].msg_len, d)) {
        owner->counters_.received++;
        owner->counters_.undecodable++;
        continue;
      }
      dispatch(d.channel, d.data, d.size);
    }
    return got;
  }
};

common::Result<std::unique_ptr<LcmTransport>> LcmTransport::create(const std::string& url,
                                                                    const std::string& channel_prefix) {
  using R = common::Result<std::unique_ptr<LcmTransport>>;
  if (channel_prefix.empty()) return R::fail("LCM channel prefix must not be empty");
  std::optional<UdpmAddress> udpm;
  if (url.rfind("udpm://", 0) == 0) {
    udpm = parseUdpm(url);
    if (!udpm) return R::fail("cannot parse the udpm URL '" + url + "' (udpm://GROUP:PORT?options)");
  }
  auto impl = std::make_unique<Impl>(url);
  if (!impl->lcm.good()) return R::fail("cannot open LCM with URL '" + url + "'");
  std::unique_ptr<LcmTransport> t(new LcmTransport(std::move(impl), channel_prefix));
  t->impl_->owner = t.get();
  if (udpm) {
    // LCM only sends: it opens its receive socket on the first subscription, which never comes.
    auto fd = openMulticastSocket(*udpm);
    if (!fd) return R::fail("cannot receive on '" + url + "': " + fd.reason());
    t->impl_->fd = fd.value();
    return R::ok(std::move(t));
  }
  // One regex subscription for our channels, every one of kChannels (LCM anchors it with ^...$).
  std::string pattern = channel_prefix + "(";
  for (const ChannelSuffix& c : kChannels) pattern += std::string(c.suffix) + (&c == std::end(kChannels) - 1 ? ")" : "|");
  lcm::Subscription* sub = t->impl_->lcm.subscribe(pattern, &Impl::onMessage, t->impl_.get());
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

int LcmTransport::handle(int timeout_ms) {
  if (impl_->fd < 0) return impl_->lcm.handleTimeout(timeout_ms);
  pollfd p{impl_->fd, POLLIN, 0};
  const int ready = poll(&p, 1, timeout_ms);
  if (ready <= 0) return ready;
  return impl_->receive(1);
}

int LcmTransport::drain(int max_messages) {
  int n = 0;
  if (impl_->fd >= 0) {
    while (n < max_messages) {
      const int got = impl_->receive(max_messages - n);
      if (got == 0) break;
      n += got;
    }
    return n;
  }
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
