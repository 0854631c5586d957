#include <vtkNew.h>
#include <vtkXMLPolyDataWriter.h>

#include <fstream>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
#include "colonflat/core/vtk_messages.h"
#include "colonflat/testdata/synthetic_pair.h"

namespace cf {
namespace fs = std::filesystem;

void write_run_dir(const ColonScan& scan, const fs::path& dir) {
  fs::create_directories(dir);
  OutputTransaction tx;
  const fs::path flat_tmp = tx.stage(dir / "flat.vtp");
  {
    VtkMessageCapture msgs;
    vtkNew<vtkXMLPolyDataWriter> w;
    w->SetFileName(flat_tmp.c_str());
    w->SetInputData(scan.flat);
    w->SetDataModeToAppended();
    if (!w->Write() || !msgs.first_problem().empty())
      throw Error((dir / "flat.vtp").string() + ": cannot write: " + msgs.first_problem());
  }
  nlohmann::json cands = nlohmann::json::array();
  for (const auto& c : scan.candidates)
    cands.push_back({{"id", c.id}, {"position_lps_mm", {c.lps.x(), c.lps.y(), c.lps.z()}},
                     {"size_mm", c.size_mm}, {"score", c.score}});
  std::ofstream(tx.stage(dir / "candidates.json"))
      << nlohmann::json{{"units", "mm"}, {"coordinate_system", "LPS"}, {"candidates", cands}}.dump(1);
  std::ofstream(tx.stage(dir / "run_report.json")) << scan.run_report.dump(1);
  tx.commit();
}

}  // namespace cf
