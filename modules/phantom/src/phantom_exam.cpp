// `colonflat phantom --exam -o DIR`: the phantom patient as a PACS exports a CT colonography study
// (docs/pacs.md): one study, a localizer, the supine and the prone scan, in nested folders.
#include <gdcmReader.h>
#include <gdcmWriter.h>

#include <system_error>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
#include "colonflat/phantom/phantom_exam.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// The localizer: a frontal projection (mean HU front to back) of the supine CT, one image in the
// plane left-right x head-feet, rows running from the head down (as scanners show a scout).
CtImage::Pointer localizer_of(const CtImage* ct) {
  const auto size = ct->GetLargestPossibleRegion().GetSize();
  const auto sp = ct->GetSpacing();
  auto img = CtImage::New();
  img->SetRegions(CtImage::SizeType{{size[0], size[2], 1}});
  CtImage::SpacingType s;
  s[0] = sp[0], s[1] = sp[2], s[2] = sp[1];
  img->SetSpacing(s);
  CtImage::DirectionType d;  // columns: x -> L, rows -> feet (-S), normal -> P
  d.Fill(0);
  d[0][0] = 1, d[2][1] = -1, d[1][2] = 1;
  img->SetDirection(d);
  CtImage::PointType top;
  ct->TransformIndexToPhysicalPoint(CtImage::IndexType{{0, itk::IndexValueType(size[1] / 2), itk::IndexValueType(size[2] - 1)}},
                                    top);
  img->SetOrigin(top);
  img->Allocate();
  for (unsigned i = 0; i < size[0]; ++i)
    for (unsigned r = 0; r < size[2]; ++r) {
      double sum = 0;
      for (unsigned j = 0; j < size[1]; ++j)
        sum += ct->GetPixel(CtImage::IndexType{{itk::IndexValueType(i), itk::IndexValueType(j),
                                                itk::IndexValueType(size[2] - 1 - r)}});
      img->SetPixel(CtImage::IndexType{{itk::IndexValueType(i), itk::IndexValueType(r), 0}}, float(sum / size[1]));
    }
  return img;
}

// An even-length DICOM text value of `vr` for `tag`.
gdcm::DataElement text_element(std::uint16_t group, std::uint16_t element, gdcm::VR vr, std::string value) {
  if (value.size() % 2) value += ' ';
  gdcm::DataElement de(gdcm::Tag(group, element));
  de.SetVR(vr);
  de.SetByteValue(value.c_str(), static_cast<std::uint32_t>(value.size()));
  return de;
}

// What write_dicom_series leaves at its defaults: SeriesNumber, and ImageType for the localizer.
void set_series_tags(const fs::path& series_dir, int number, const std::string& image_type) {
  for (const auto& e : fs::directory_iterator(series_dir)) {
    gdcm::Reader r;
    r.SetFileName(e.path().c_str());
    if (!r.Read()) throw Error(e.path().string() + ": cannot read back the slice just written");
    gdcm::DataSet& ds = r.GetFile().GetDataSet();
    ds.Replace(text_element(0x0020, 0x0011, gdcm::VR::IS, std::to_string(number)));
    if (!image_type.empty()) ds.Replace(text_element(0x0008, 0x0008, gdcm::VR::CS, image_type));
    gdcm::Writer w;
    w.SetFile(r.GetFile());
    w.SetFileName(e.path().c_str());
    if (!w.Write()) throw Error(e.path().string() + ": cannot write");
  }
}

// One series of the exam: the patient, the study and its own series and frame of reference UIDs.
DicomWriteOptions series_options(std::uint64_t seed, const std::string& what, const std::string& frame,
                                 const std::string& position) {
  DicomWriteOptions w;
  w.uid_seed = seed;
  w.study_uid = derived_uid(seed, "study");
  w.series_uid = derived_uid(seed, "series-" + what);
  w.frame_of_reference_uid = derived_uid(seed, "frame-" + frame);  // each scan: the patient moved
  w.patient_position = position;
  w.series_description = "ColonFlat phantom " + what;
  return w;
}

}  // namespace

void write_phantom_exam(const Phantom& supine, const Phantom& prone, const fs::path& dir) {
  if (!supine.ct || !prone.ct) throw Error("write_phantom_exam: empty phantom");
  const std::uint64_t seed = supine.description.value("seed", std::uint64_t(1));
  OutputTransaction tx;
  const fs::path exam = tx.stage(dir / "exam");
  std::error_code ec;
  fs::create_directories(exam / "ST0", ec);
  if (ec) throw Error((dir / "exam").string() + ": cannot create folder: " + ec.message());
  write_dicom_series(localizer_of(supine.ct.GetPointer()).GetPointer(), exam / "ST0" / "SE1",
                     series_options(seed, "localizer", "supine", supine.patient_position));
  set_series_tags(exam / "ST0" / "SE1", 1, "ORIGINAL\\PRIMARY\\LOCALIZER");
  write_dicom_series(supine.ct.GetPointer(), exam / "ST0" / "SE2",
                     series_options(seed, "supine", "supine", supine.patient_position));
  set_series_tags(exam / "ST0" / "SE2", 2, "");
  write_dicom_series(prone.ct.GetPointer(), exam / "ST0" / "SE3",
                     series_options(seed, "prone", "prone", prone.patient_position));
  set_series_tags(exam / "ST0" / "SE3", 3, "");
  write_phantom(supine, tx.stage(dir / "supine"), "truth");
  write_phantom(prone, tx.stage(dir / "prone"), "truth");
  tx.commit();
}

}  // namespace cf
