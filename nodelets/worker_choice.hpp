#pragma once
// The operator's choice of the worker in the Perception nodelet (docs/perception.md "Choosing the
// worker"): the candidates message of a detection round and the ~select_worker service's answer.
// The decisions are the core's (perception::WorkerTracker::selectWorker / selectCandidate / unlock).
#include <string>

#include <opencv2/core.hpp>

#include "gesture_formation/SelectWorker.h"
#include "gesture_formation/WorkerCandidates.h"
#include "gesture_formation/perception/worker_tracker.hpp"

namespace gesture_formation::nodelets {

/// The people of one detection round; `round` numbers the rounds (header.seq).
inline gesture_formation::WorkerCandidates toCandidates(const std_msgs::Header& header, std::uint32_t round,
                                                        const perception::TrackStep& t, bool locked) {
  gesture_formation::WorkerCandidates c;
  c.header = header;
  c.header.seq = round;
  for (const perception::Detection& d : t.detections) {
    c.u.push_back(d.box_px.x);
    c.v.push_back(d.box_px.y);
    c.w.push_back(d.box_px.width);
    c.h.push_back(d.box_px.height);
    c.score.push_back(d.score);
  }
  c.worker = t.worker_detection;
  c.worker_id = t.found ? t.id : -1;
  c.locked = locked;
  return c;
}

/// ~select_worker: unlock, a candidate of the last round (`round`: the last published header.seq),
/// or an image point. Refused (accepted false, nothing changed) with the reason.
inline gesture_formation::SelectWorker::Response selectWorker(perception::WorkerTracker& tracker,
                                                              const gesture_formation::SelectWorker::Request& req,
                                                              std::uint32_t round) {
  gesture_formation::SelectWorker::Response res;
  if (req.unlock) {
    tracker.unlock();
    res.accepted = true;
    res.message = "the operator's choice ended: after a loss the tracker may take the best-scoring person";
    return res;
  }
  if (req.candidate >= 0 && req.candidates_seq != round) {
    res.message = "candidates_seq " + std::to_string(req.candidates_seq) + " is not the last detection round (" +
                  std::to_string(round) + "): choose again from the newest WorkerCandidates";
    return res;
  }
  const auto chosen = req.candidate >= 0
                          ? tracker.selectCandidate(req.candidate)
                          : tracker.selectWorker(cv::Point2f(static_cast<float>(req.u), static_cast<float>(req.v)));
  if (!chosen) {
    res.message = chosen.reason();
    return res;
  }
  res.accepted = true;
  res.u = chosen->x;
  res.v = chosen->y;
  res.w = chosen->width;
  res.h = chosen->height;
  res.message = "the operator chose the worker at (" + std::to_string(static_cast<int>(res.u)) + ", " +
                std::to_string(static_cast<int>(res.v)) + ") " + std::to_string(static_cast<int>(res.w)) + "x" +
                std::to_string(static_cast<int>(res.h)) + " px; the tracker keeps that person until unlock";
  return res;
}

}  // namespace gesture_formation::nodelets
