// Writes valid encodings as seed inputs: gf_fuzz_make_seeds <corpus_dir>
// (fuzz/corpus/<target>/seed_*). Run by tools/fuzz/run_fuzzers.sh --seeds.
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "fuzz_common.hpp"
#include "gesture_formation/comm/map_update.hpp"
#include "gesture_formation/comm/payloads.hpp"
#include "gesture_formation/comm/signer.hpp"
#include "gesture_formation/lcm_bridge/lcm_transport.hpp"

using namespace gesture_formation;
using namespace gesture_formation::comm;

namespace {

void write(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

std::vector<std::uint8_t> withPrefix(std::uint8_t prefix, const std::vector<std::uint8_t>& b) {
  std::vector<std::uint8_t> out{prefix};
  out.insert(out.end(), b.begin(), b.end());
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <corpus_dir>\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  Heartbeat hb;
  hb.uav_index = 1;
  hb.worker_visible = true;
  WorkerStateMessage ws;
  ws.p_world = {1, 2, 3};
  ws.covariance_diag = {0.1, 0.1, 0.1, 1, 1, 1};
  PlanMessage plan;
  plan.plan.uav_index = 1;
  plan.plan.samples.resize(3);
  plan.fallback = true;
  FormationParamsMessage params;
  params.version = 3;
  formation::FormationCommand cmd;
  cmd.id = {"operator", 7};
  cmd.target = formation::CommandTarget::list({1, 2});
  cmd.parameter = formation::Parameter::kGamma;
  cmd.amount = 5;
  GestureObservationMessage obs;  // with a skeleton (view_fusion.confirm_3d)
  obs.uav_index = 1;
  obs.gesture_id = 2;
  obs.probabilities = {0.1, 0.1, 0.6, 0.1, 0.1};
  obs.geometry_known = true;
  obs.distance_m = 9.0;
  obs.skeleton.emplace();
  for (std::size_t k = 0; k < obs.skeleton->skeleton.x.size(); ++k) {
    obs.skeleton->skeleton.x[k] = 300.0 + 4.0 * static_cast<double>(k);
    obs.skeleton->skeleton.y[k] = 200.0 + 6.0 * static_cast<double>(k);
    obs.skeleton->skeleton.c[k] = 0.8;
  }
  obs.skeleton->p_world_camera = {8.0, 1.0, 3.0};
  // in the order of MessageType (1..6); fuzz_payloads: prefix i % 5 for the first five, 255 for the observation
  const std::vector<std::vector<std::uint8_t>> payloads = {
      encodePayload(hb).value(), encodePayload(ws).value(), encodePayload(plan).value(),
      encodePayload(params).value(), encodePayload(cmd).value(), encodePayload(obs).value()};
  for (std::size_t i = 0; i < payloads.size(); ++i) {
    write(dir + "/payloads/seed_" + std::to_string(i), withPrefix(static_cast<std::uint8_t>(i < 5 ? i : 255), payloads[i]));
  }
  MapUpdate map_update;
  map_update.uav_index = 1;
  map_update.sequence = 7;
  map_update.delta.stamp_s = 12.5;
  map_update.delta.resolution_m = 0.2;
  map_update.delta.occupied = {{{32800, 32790, 32770}}, {{32801, 32790, 32770}}};
  map_update.delta.free = {{{32760, 32770, 32771}}};
  write(dir + "/payloads/seed_map_update", withPrefix(250, encodePayload(map_update).value()));
  KeyEntry k;
  k.id = 2;
  k.key = gf_fuzz::fuzzKey(2);
  Signer signer(1, KeyRing::create({k}, 2).value(), 1);
  for (std::size_t i = 0; i < payloads.size(); ++i) {
    const auto sealed = signer.seal(static_cast<MessageType>(i + 1), payloads[i], 100.0).value();
    write(dir + "/lcm_envelope/seed_" + std::to_string(i), lcm_bridge::encodeLcmEnvelope(sealed));
    // fuzz_envelope script: mode 0 (raw bytes), now step 0, length, the bytes.
    std::vector<std::uint8_t> script{0x00, 0x00, 0x00};
    script.insert(script.end(), sealed.begin(), sealed.end());
    write(dir + "/envelope/seed_" + std::to_string(i), script);
  }
  // The leadership payload (prefix 251): a vote request with its estimate age, and a granted reply.
  formation::LeadershipMessage vote;
  vote.kind = formation::LeadershipMessageKind::kVoteRequest;
  vote.term = 2;
  vote.from = 1;
  vote.sent_s = 61.5;
  vote.estimate_age_s = 0.2;
  formation::LeadershipMessage reply = vote;
  reply.kind = formation::LeadershipMessageKind::kVoteReply;
  reply.from = 2;
  reply.to = 1;
  reply.echo_s = 61.5;
  reply.granted = true;
  reply.estimate_age_s = std::numeric_limits<double>::infinity();
  int k_lead = 0;
  for (const auto& m : {vote, reply}) {
    const auto b = encodePayload(m).value();
    write(dir + "/payloads/seed_leadership_" + std::to_string(k_lead), withPrefix(251, b));
    const auto sealed = signer.seal(MessageType::kLeadership, b, 100.0).value();
    write(dir + "/lcm_envelope/seed_leadership_" + std::to_string(k_lead++), lcm_bridge::encodeLcmEnvelope(sealed));
  }
  return 0;
}
