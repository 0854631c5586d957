#pragma once
// Recognising ColonFlat's own polydata outputs for `colonflat info` (internal to the pipeline).
#include <string>

#include <nlohmann/json.hpp>

namespace cf {

enum class OwnKind { kNone, kLoops, kFlat };
struct OwnOutput {
  OwnKind kind = OwnKind::kNone;
  nlohmann::json info;
};

// kLoops: a .vtp of polylines without faces (loops.vtp); kFlat: a .vtp with FlatSegments field
// data (flat.vtp); kNone otherwise (also when the file cannot be read: the mesh path reports it).
OwnOutput inspect_own_output(const std::string& file);
std::string own_output_text(const OwnOutput& o);

}  // namespace cf
