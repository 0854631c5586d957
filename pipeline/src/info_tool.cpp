// `colonflat info FILE`: topology and defects of a mesh (volumes: see the volume module).
#include <iostream>

#include "colonflat/core/error.h"
#include "colonflat/core/mesh_artifact.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/pipeline/registry.h"
#include "info_outputs.h"
#if __has_include("colonflat/volume/volume_io.h")
#include "colonflat/volume/volume_io.h"
#define COLONFLAT_HAS_VOLUME 1
#endif

namespace cf {
namespace {

class InfoTool : public Tool {
 public:
  std::string name() const override { return "info"; }
  std::string summary() const override {
    return "mesh topology and defects (V, E, F, genus, ...), or volume geometry and HU range";
  }
  int run(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) override {
    CLI::App app("Reports a mesh's topology (conventions: docs/conventions.md) and every defect with counts "
                 "and example ids. Exit 0 when the mesh is a valid closed 2-manifold (or, with "
                 "--allow-boundary, a 2-manifold with boundary), 3 when it has defects or cannot be read.",
                 "colonflat info");
    app.set_version_flag("--version", colonflat_version());
    std::string file, series;
    bool json = false, allow_boundary = false;
    app.add_option("file", file,
                   "mesh file (" + mesh_format_list() + "), or a CT volume (NRRD, NIfTI, MHA/MHD, DICOM file or folder)")
        ->required()
        ->type_name("FILE");
    app.add_option("--series", series, "DICOM folder with several series: the SeriesInstanceUID to read")
        ->type_name("UID");
    app.add_flag("--json", json, "print the report as JSON on stdout");
    app.add_flag("--allow-boundary", allow_boundary, "an open surface (boundary loops) is not a defect");
    return run_cli(app, name(), args, out, err, [&]() -> int {
#ifdef COLONFLAT_HAS_VOLUME
      if (!mesh_format_from_path(file) && try_volume_info(file, json, out, series)) return kExitOk;
#endif
      const OwnOutput own = inspect_own_output(file);
      if (own.kind == OwnKind::kLoops) {
        if (json) out << nlohmann::json{{"file", file}, {"valid", true}, {"loops", own.info}}.dump(2) << "\n";
        else out << file << "\n" << own_output_text(own);
        return kExitOk;
      }
      if (own.kind == OwnKind::kFlat) {
        allow_boundary = true;  // a flat map is an open surface by construction
        if (!json) out << own_output_text(own);
      }
      PolygonSoup soup = read_polygon_soup(file);
      MeshDiagnosis diag = diagnose_soup(soup);
      std::optional<TopologyReport> topo;
      if (!diag.has_at_least(Severity::kFatal)) {
        LoadPolicy policy;
        TriangleList tris = soup_to_triangles(soup, policy, diag);
        topo = analyze_topology(tris);
        add_topology_findings(*topo, allow_boundary, diag);
        add_orientation_findings(std::move(tris), *topo, diag);
      }
      const bool ok = !diag.has_at_least(Severity::kDefect);
      if (json) {
        nlohmann::json j = {{"file", file},
                            {"kind", own.kind == OwnKind::kFlat ? own.info : nlohmann::json("mesh")},
                            {"valid", ok},
                            {"topology", topo ? topology_to_json(*topo) : nlohmann::json(nullptr)},
                            {"findings", diagnosis_to_json(diag)}};
        out << j.dump(2) << "\n";
      } else {
        out << file << "\n";
        if (topo) out << topology_to_text(*topo);
        for (const auto& f : diag.findings) {
          static const char* tag[] = {"note", "repaired", "defect", "fatal"};
          out << tag[static_cast<int>(f.severity)] << ": " << f.message << "\n";
        }
      }
      if (!ok) {
        const bool fatal = diag.has_at_least(Severity::kFatal);
        throw InputError(file, std::string(fatal ? "unusable mesh: " : "not a valid ") +
                                   (fatal ? "" : (allow_boundary ? "2-manifold: " : "closed 2-manifold: ")) +
                                   diag.summary(Severity::kDefect));
      }
      return kExitOk;
    });
  }
};

}  // namespace

std::unique_ptr<Tool> make_info_tool() { return std::make_unique<InfoTool>(); }

}  // namespace cf
