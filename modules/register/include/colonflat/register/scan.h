#pragma once
// One scan of a supine/prone pair as the register stage sees it: the flat map of a run
// (flat.vtp, contract 1 in docs/register.md) and its polyp candidates (candidates.json, falling
// back to polyps.json). Every geometric quantity is in LPS millimetres.
//
//   cf::ColonScan s = cf::read_run_dir("runs/supine");   // throws cf::InputError
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

namespace cf {

// A polyp candidate (or a ground-truth polyp) of one scan.
struct ScanCandidate {
  int id = 0;
  Eigen::Vector3d lps{0, 0, 0};  // LPS mm ("position_lps_mm", else "center_lps_mm")
  double size_mm = 0;            // "size_mm", else "diameter_mm"; 0 when unknown
  double score = 1;              // 0..1; 1 when the file has none (truth lists)
};

// The data of one run used for registration. Per-vertex arrays have one entry per flat.vtp point.
struct ColonScan {
  std::string name;                        // run directory or file, for messages
  vtkSmartPointer<vtkPolyData> flat;       // flat.vtp as read (kept to write the correspondence .vtp)
  std::vector<Eigen::Vector2d> uv;         // flat map position (x along, y around), mm
  std::vector<Eigen::Vector3d> lps;        // 3D wall position, LPS mm
  std::vector<Eigen::Vector3d> normal;     // unit normal out of the lumen; zero when absent
  std::vector<int> segment;                // segment id per vertex; all 0 when absent
  std::vector<double> centreline_mm;       // contract 1 "centreline_mm"; empty when absent
  nlohmann::json segments = nlohmann::json::array();  // FlatSegments "segments" (may be empty)
  std::vector<ScanCandidate> candidates;
  std::string candidates_file;             // file the candidates came from ("" = none found)
  nlohmann::json run_report = nlohmann::json::object();  // run_report.json, {} when absent
};

// The FlatSegments entry of band `id` (nullptr when the scan has none).
const nlohmann::json* segment_entry(const ColonScan& scan, int id);
// A FlatSegments entry of a side branch (kind "branch").
bool is_branch_entry(const nlohmann::json& seg);
// Band `id` is a side branch (FlatSegments kind "branch").
bool is_branch(const ColonScan& scan, int id);
// Band `id` was cut off around tissue (FlatSegments holds "tissue": a strand stump left where denoise
// cut a tissue bridge, not a pouch of lumen): never a stretch of the colon's course.
bool holds_tissue(const ColonScan& scan, int id);

// Reads DIR/flat.vtp (required), DIR/candidates.json or DIR/polyps.json (optional) and
// DIR/run_report.json (optional). Throws InputError naming the offending file.
ColonScan read_run_dir(const std::filesystem::path& dir);

// Fills the per-vertex arrays of a scan from a flat map polydata (needs point data
// position_lps_mm with 3 components; everything else optional). Throws InputError(name, ...).
ColonScan scan_from_polydata(vtkSmartPointer<vtkPolyData> flat, const std::string& name);

// Candidates from the render stage's JSON ({"candidates": [...]}) or a plain list (phantom truth).
// Throws InputError(name, ...) on a malformed entry.
std::vector<ScanCandidate> scan_candidates_from_json(const nlohmann::json& j, const std::string& name);

}  // namespace cf
