// What holds a local piece's steps (held_steps.h).
#include "held_steps.h"

#include <algorithm>
#include <utility>

#include "face_blocks.h"

namespace cf::flat_detail {

HeldSteps::HeldSteps(const Surface& s, const Embedding& emb, std::function<double()> hidden, double tolerance)
    : s_(s), emb_(emb), hidden_(std::move(hidden)), tolerance_(tolerance) {}

double HeldSteps::cut(const std::vector<int>& judged, const std::vector<V2>& trial) {
  limit_.resize(judged.size());
  const double t = std::max(0.0, block_min(judged.size(), 1.0, [&](std::size_t begin, std::size_t end) {
                              double m = 1.0;
                              for (std::size_t i = begin; i < end; ++i)
                                m = std::min(m, limit_[i] = face_step_limit(s_, emb_, trial, judged[i], 0.0));
                              return m;
                            }));
  const auto least = std::min_element(limit_.begin(), limit_.end());
  limiting_ = least != limit_.end() && *least < 1.0 ? judged[std::size_t(least - limit_.begin())] : -1;
  return t;
}

bool HeldSteps::stop(double limit) {
  largest_ = std::max(largest_, limit);
  const bool recurs = limiting_ >= 0 && std::find(recent_.begin(), recent_.end(), limiting_) != recent_.end();
  streak_ = limit < kHeldStep && recurs ? streak_ + 1 : 0;
  recent_.push_back(limiting_);
  if (int(recent_.size()) > kRecent) recent_.erase(recent_.begin());
  if (streak_ == 0) last_hidden_ = -1;
  if (streak_ < kStallSteps || streak_ % (kStallSteps / 4) != 0 || !hidden_) return false;
  const double hidden = hidden_(), before = last_hidden_;
  last_hidden_ = hidden;
  return hidden <= tolerance_ && before >= 0 && !(hidden < before);
}

}  // namespace cf::flat_detail
