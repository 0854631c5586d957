// generate_phantom: options -> layout (phantom_layout.cpp, phantom_extras.cpp) -> label volume
// (phantom_paint.cpp, phantom_fill.cpp) -> CT (blur + noise), ground truth and description; the
// JSON forms of the truth and write_phantom.
#include "colonflat/phantom/phantom.h"

#include <itkSmoothingRecursiveGaussianImageFilter.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
#include "colonflat/core/progress.h"
#include "colonflat/core/tool.h"
#include "phantom_description.h"
#include "phantom_model.h"

namespace fs = std::filesystem;

namespace cf {

using namespace phantom_detail;

namespace {

void validate(const PhantomOptions& o) {
  if (o.size != "small" && o.size != "medium" && o.size != "full")
    throw UsageError("--size must be small, medium or full (got '" + o.size + "')");
  if (!(o.noise_hu >= 0 && o.noise_hu <= 500)) throw UsageError("--noise must be in [0, 500] HU");
  if (!(o.blur_mm >= 0 && o.blur_mm <= 5)) throw UsageError("--blur must be in [0, 5] mm");
  if (o.position != "supine" && o.position != "prone")
    throw UsageError("--position must be supine or prone (got '" + o.position + "')");
  if (o.fully_tagged_segments < 0 || o.fully_tagged_segments > 3)
    throw UsageError("--fully-tagged-segments must be in [0, 3] (got " + std::to_string(o.fully_tagged_segments) + ")");
}

}  // namespace

namespace phantom_detail {

template <class TImage>
typename TImage::Pointer image_on(const Grid& g) {
  auto im = TImage::New();
  typename TImage::SizeType sz{{std::size_t(g.n[0]), std::size_t(g.n[1]), std::size_t(g.n[2])}};
  im->SetRegions(sz);
  const double sp[3] = {g.sp[0], g.sp[1], g.sp[2]};
  const double org[3] = {g.org[0], g.org[1], g.org[2]};
  im->SetSpacing(sp);
  im->SetOrigin(org);
  im->Allocate();
  return im;
}

// The sharp HU volume and the truth images from the materials; `mat` is released.
CtImage::Pointer materials_to_images(const Model& md, std::vector<unsigned char>& mat, Phantom& out, VolumeCounts& counts) {
  const Grid& g = md.g;
  CtImage::Pointer sharp = image_on<CtImage>(g);
  out.lumen = image_on<MaskImage>(g);
  out.labels = image_on<MaskImage>(g);
  float* hu = sharp->GetBufferPointer();
  unsigned char* lm = out.lumen->GetBufferPointer();
  unsigned char* lb = out.labels->GetBufferPointer();
  for (std::size_t q = 0; q < mat.size(); ++q) {
    hu[q] = float(hu_of(mat[q], md));
    lm[q] = is_lumen(mat[q]) ? 1 : 0;
    lb[q] = truth_of(mat[q]);
    counts.lumen += lm[q];
    counts.fluid += mat[q] >= kFluid0;
    ++counts.by_label[lb[q]];
  }
  std::vector<unsigned char>().swap(mat);
  return sharp;
}

// Partial-volume blur (Gaussian) and noise (per-slice deterministic streams), rounded and clamped.
CtImage::Pointer blur_and_noise(CtImage::Pointer sharp, double noise_hu, double blur_mm, std::uint64_t seed, const Grid& g) {
  const double blur = blur_mm > 0 ? blur_mm : std::max(0.45, 0.6 * std::min(g.sp[0], g.sp[1]));
  using Smooth = itk::SmoothingRecursiveGaussianImageFilter<CtImage, CtImage>;
  auto sm = Smooth::New();
  sm->SetInput(sharp);
  sm->SetSigma(blur);
  sm->SetNumberOfWorkUnits(2);
  sm->Update();
  CtImage::Pointer ct = sm->GetOutput();
  ct->DisconnectPipeline();
  sharp = nullptr;
  float* hu = ct->GetBufferPointer();
  const std::size_t slice = std::size_t(g.n[0]) * g.n[1];
  parallel_for(g.n[2], [&](int k0, int k1) {
    for (int k = k0; k < k1; ++k) {
      Rng r(seed * 1000003ull + std::uint64_t(k) * 7919ull + 17);
      for (std::size_t q = std::size_t(k) * slice; q < std::size_t(k + 1) * slice; ++q) {
        const double v = hu[q] + (noise_hu > 0 ? noise_hu * r.normal() : 0.0);
        hu[q] = float(std::clamp(std::nearbyint(v), -1024.0, 3071.0)) + 0.0f;  // no -0
      }
    }
  });
  return ct;
}

}  // namespace phantom_detail

namespace {

// Arc length along this case's centreline at material position s.
double true_arc(const Path& P, double s) {
  const std::size_t i = std::min(P.p.size() - 2, std::size_t(std::max(0.0, s)));
  const double t = std::clamp(s - P.s[i], 0.0, 1.0);
  return P.arc[i] * (1 - t) + P.arc[i + 1] * t;
}

}  // namespace

Phantom generate_phantom(const PhantomOptions& o) {
  validate(o);
  Model md;
  PhantomLayout(o, md).run();
  phase_done("colon layout");
  std::vector<unsigned char> mat(md.g.voxels());
  paint_body(md.g, mat);
  PhantomPainter(md, mat).run();
  phase_done("tissues painted");
  Phantom out;
  VolumeCounts counts;
  CtImage::Pointer sharp = materials_to_images(md, mat, out, counts);
  out.ct = blur_and_noise(sharp, o.noise_hu, o.blur_mm, o.seed, md.g);
  phase_done("CT with blur and noise");
  out.patient_position = md.gravity > 0 ? "HFS" : "HFP";
  set_patient_position(out.ct.GetPointer(), out.patient_position);
  for (const Polyp& p : md.polyps) {
    PhantomPolyp gt = p.gt;
    gt.centreline_mm = gt.arclength_mm = true_arc(md.path, p.gt.arclength_mm);
    out.polyps.push_back(gt);
  }
  const Path& P = md.path;
  for (std::size_t i = 0; i < P.p.size(); i += 2)
    out.centerline.push_back({{P.p[i].x(), P.p[i].y(), P.p[i].z()}, radius_at(md, i, 0), P.arc[i], kSegmentNames[P.seg[i]]});
  out.noise_sites = md.sites;
  out.description = describe_phantom(o, md, counts);
  return out;
}

nlohmann::json polyps_json(const Phantom& p) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& q : p.polyps)
    a.push_back({{"id", q.id},
                 {"center_lps_mm", q.center_lps_mm},
                 {"position_lps_mm", q.center_lps_mm},
                 {"diameter_mm", q.diameter_mm},
                 {"type", q.type},
                 {"segment", q.segment},
                 {"arclength_mm", q.arclength_mm},
                 {"centreline_mm", q.centreline_mm},
                 {"patient_position", p.patient_position}});
  return a;
}

nlohmann::json centerline_json(const Phantom& p) {
  nlohmann::json pts = nlohmann::json::array();
  for (const auto& c : p.centerline)
    pts.push_back({{"p_lps_mm", c.p_lps_mm}, {"radius_mm", c.radius_mm}, {"arclength_mm", c.arclength_mm}, {"segment", c.segment}});
  return {{"units", "mm"}, {"coordinate_system", "LPS"}, {"from", "rectum"}, {"to", "cecum"},
          {"patient_position", p.patient_position}, {"points", pts}};
}

nlohmann::json noise_sites_json(const Phantom& p) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& s : p.noise_sites)
    a.push_back({{"id", s.id}, {"type", s.type}, {"center_lps_mm", s.center_lps_mm}, {"size_mm", s.size_mm}, {"effect", s.effect}});
  return a;
}

// format "truth" (write_phantom_exam): every file but the CT, which the exam holds.
void write_phantom(const Phantom& p, const fs::path& dir, const std::string& format) {
  if (format != "nrrd" && format != "dicom" && format != "truth")
    throw UsageError("--format must be nrrd or dicom (got '" + format + "')");
  if (!p.ct || !p.lumen) throw Error("write_phantom: empty phantom");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir.string() + ": cannot create folder: " + ec.message());
  OutputTransaction tx;
  if (format == "nrrd") volume_artifact().write(std::any(p.ct), tx.stage(dir / "ct.nrrd"), dir / "ct.nrrd");
  mask_artifact().write(std::any(p.lumen), tx.stage(dir / "lumen_mask.nrrd"), dir / "lumen_mask.nrrd");
  if (p.labels) mask_artifact().write(std::any(p.labels), tx.stage(dir / "labels.nrrd"), dir / "labels.nrrd");
  auto put_json = [&](const char* name, const nlohmann::json& j) {
    std::ofstream f(tx.stage(dir / name));
    f << j.dump(2) << "\n";
    if (!f) throw Error((dir / name).string() + ": cannot write");
  };
  put_json("polyps.json", polyps_json(p));
  put_json("centerline.json", centerline_json(p));
  put_json("noise_sites.json", noise_sites_json(p));
  nlohmann::json d = p.description;
  d["files"]["ct"] = format == "nrrd" ? "ct.nrrd" : format == "dicom" ? "dicom/" : "../exam/";
  put_json("phantom.json", d);
  if (format == "dicom") {
    const fs::path dd = dir / "dicom";
    if (fs::exists(dd)) fs::remove_all(dd, ec);
    DicomWriteOptions w;
    w.uid_seed = p.description.value("seed", std::uint64_t(1));
    w.patient_position = p.patient_position;
    write_dicom_series(p.ct.GetPointer(), dd, w);
  }
  tx.commit();
}

}  // namespace cf
