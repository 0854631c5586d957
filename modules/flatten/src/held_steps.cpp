// What holds a local piece's steps (held_steps.h).
#include "held_steps.h"

#include <algorithm>
#include <utility>

#include "face_blocks.h"

namespace cf::flat_detail {

HeldSteps::HeldSteps(const Surface& s, const Embedding& emb, std::function<double()> hidden, double tolerance,
                     bool leave_stuck)
    : s_(s), emb_(emb), hidden_(std::move(hidden)), tolerance_(tolerance), leave_stuck_(leave_stuck) {}

double HeldSteps::cut(const std::vector<int>& judged, const std::vector<V2>& trial) {
  // Per block of judged faces: its smallest limit and the first face holding it; the blocks read in
  // order, so the face is the first smallest of all (a serial pass over every face's limit before).
  std::vector<std::pair<double, std::size_t>> least(std::max<std::size_t>(1, face_blocks(judged.size())), {1e300, 0});
  for_each_block(judged.size(), [&](std::size_t begin, std::size_t end) {
    std::pair<double, std::size_t>& m = least[begin / kFaceBlock];
    for (std::size_t i = begin; i < end; ++i) {
      const double limit = face_step_limit(s_, emb_, trial, judged[i], 0.0);
      if (limit < m.first) m = {limit, i};
    }
  });
  std::pair<double, std::size_t> m = least.front();
  for (const auto& b : least)
    if (b.first < m.first) m = b;
  limiting_ = m.first < 1.0 ? judged[m.second] : -1;
  return std::max(0.0, std::min(1.0, m.first));
}

const char* HeldSteps::stop(double limit, double before, double after, int steps_left) {
  largest_ = std::max(largest_, limit);
  if (stuck_at(limit, before, after, steps_left)) return "stuck";
  const bool recurs = limiting_ >= 0 && std::find(recent_.begin(), recent_.end(), limiting_) != recent_.end();
  streak_ = limit < kHeldStep && recurs ? streak_ + 1 : 0;
  recent_.push_back(limiting_);
  if (int(recent_.size()) > kRecent) recent_.erase(recent_.begin());
  if (streak_ == 0) last_hidden_ = -1;
  if (streak_ < kStallSteps || streak_ % (kStallSteps / 4) != 0 || !hidden_) return nullptr;
  const double hidden = hidden_(), earlier = last_hidden_;
  last_hidden_ = hidden;
  return hidden <= tolerance_ && earlier >= 0 && !(hidden < earlier) ? "held" : nullptr;
}

// The stuck streak (held_steps.h), judged after kStallSteps steps and every kStallSteps / 4 after,
// at the rate of its last kStallSteps steps.
bool HeldSteps::stuck_at(double limit, double before, double after, int steps_left) {
  if (!leave_stuck_ || !hidden_ || !(limit < kStuckStep)) {
    stuck_energies_.clear(), stuck_ = 0;
    return false;
  }
  if (stuck_energies_.empty()) stuck_energies_.push_back(before), stuck_hidden_ = hidden_();
  stuck_energies_.push_back(after);
  if (stuck_energies_.size() > std::size_t(kStallSteps) + 1) stuck_energies_.erase(stuck_energies_.begin());
  if (++stuck_ % (kStallSteps / 4) != 0 || stuck_energies_.size() <= std::size_t(kStallSteps)) return false;
  const double first = stuck_energies_.front(), fall_per_step = (first - after) / (first * kStallSteps);
  return fall_per_step * steps_left < kStuckFall && !(hidden_() < stuck_hidden_);
}

}  // namespace cf::flat_detail
