#pragma once
// How the denoise stage hands two jobs to its helper thread: the first runs on the calling thread,
// the second on the helper at once, and the call returns when both are done (neither may throw).
// An empty RunBoth means one thread: the caller runs both jobs itself, in order.
#include <functional>

namespace cf {

using RunBoth = std::function<void(const std::function<void()>&, const std::function<void()>&)>;

}  // namespace cf
