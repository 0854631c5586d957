#include "colonflat/phantom/phantom.h"

#include "colonflat/core/error.h"

namespace cf {

Phantom generate_phantom(const PhantomOptions& opts) { throw Error("generate_phantom: not implemented yet"); }
void write_phantom(const Phantom& p, const std::filesystem::path& dir, const std::string& format) {
  throw Error("write_phantom: not implemented yet");
}
nlohmann::json polyps_json(const Phantom& p) { return {}; }
nlohmann::json centerline_json(const Phantom& p) { return {}; }
nlohmann::json noise_sites_json(const Phantom& p) { return {}; }

}  // namespace cf
