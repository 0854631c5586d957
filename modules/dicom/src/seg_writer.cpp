// The lumen mask as a DICOM Segmentation (binary SEG, DCMTK dcmseg) on the source CT's slices.
#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcuid.h>
#include <dcmtk/dcmfg/fgderimg.h>
#include <dcmtk/dcmfg/fgfracon.h>
#include <dcmtk/dcmfg/fgpixmsr.h>
#include <dcmtk/dcmfg/fgplanor.h>
#include <dcmtk/dcmfg/fgplanpo.h>
#include <dcmtk/dcmiod/iodreferences.h>
#include <dcmtk/dcmseg/segdoc.h>
#include <dcmtk/dcmseg/segment.h>

#include <cmath>
#include <iomanip>
#include <memory>
#include <sstream>

#include "colonflat/core/error.h"
#include "colonflat/dicom/results.h"
#include "dicom_common.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

std::string ds_text(double v) {
  std::ostringstream s;
  s << std::setprecision(10) << v;
  return s.str().substr(0, 16);  // DS: at most 16 characters
}

void check(const OFCondition& c, const fs::path& file, const std::string& what) {
  if (c.bad()) throw Error(file.string() + ": cannot build the segmentation (" + what + "): " + c.text());
}

// Builds the SEG step by step: the object with its study, the segment, the shared geometry, one
// frame per slice holding lumen, the references.
class SegBuilder {
 public:
  SegBuilder(const MaskImage* mask, const SourceSeries& src, fs::path file)
      : mask_(mask), src_(src), file_(std::move(file)) {}

  std::string build(int series_number) {
    create_object(series_number);
    add_segment();
    add_shared_geometry();
    add_frames();
    add_references();
    return save();
  }

 private:
  void create_object(int series_number) {
    const auto size = mask_->GetLargestPossibleRegion().GetSize();
    IODGeneralEquipmentModule::EquipmentInfo eq("ColonFlat", "ColonFlat", "1", COLONFLAT_DICOM_VERSION);
    ContentIdentificationMacro ci("1", "COLON_LUMEN", "Colon lumen (air and tagged fluid)", "ColonFlat");
    DcmSegmentation* seg = nullptr;
    check(DcmSegmentation::createBinarySegmentation(seg, Uint16(size[1]), Uint16(size[0]), eq, ci), file_, "create");
    seg_.reset(seg);
    DcmFileFormat source;
    check(source.loadFileUntilTag(src_.first_file.c_str(), EXS_Unknown, EGL_noChange, DCM_MaxReadLength, ERM_fileOnly,
                                  DCM_PixelData),
          src_.first_file, "read the source");
    check(seg_->importFromSourceImage(*source.getDataset()), file_, "patient and study of the source");
    seg_->getSeries().setSeriesInstanceUID(new_uid().c_str());
    seg_->getSeries().setSeriesNumber(std::to_string(series_number).c_str());
    seg_->getSeries().setSeriesDescription("ColonFlat colon lumen segmentation");
    seg_->getFrameOfReference().setFrameOfReferenceUID(src_.frame_of_reference_uid.c_str());
  }

  void add_segment() {
    DcmSegment* segment = nullptr;
    check(DcmSegment::create(segment, "Colon lumen", CodeSequenceMacro("91723000", "SCT", "Anatomical Structure"),
                             CodeSequenceMacro("71854001", "SCT", "Colon"), DcmSegTypes::SAT_AUTOMATIC, "ColonFlat"),
          file_, "segment");
    check(seg_->addSegment(segment, segment_number_), file_, "add the segment");
  }

  void add_shared_geometry() {
    const auto sp = mask_->GetSpacing();
    FGPixelMeasures measures;
    measures.setPixelSpacing((ds_text(sp[1]) + "\\" + ds_text(sp[0])).c_str());
    measures.setSliceThickness(ds_text(sp[2]).c_str());
    measures.setSpacingBetweenSlices(ds_text(sp[2]).c_str());
    check(seg_->addForAllFrames(measures), file_, "pixel measures");
    const auto& o = src_.orientation;
    std::unique_ptr<FGPlaneOrientationPatient> orient(FGPlaneOrientationPatient::createMinimal(
        ds_text(o[0]).c_str(), ds_text(o[1]).c_str(), ds_text(o[2]).c_str(), ds_text(o[3]).c_str(),
        ds_text(o[4]).c_str(), ds_text(o[5]).c_str()));
    check(seg_->addForAllFrames(*orient), file_, "plane orientation");
    const std::string dim_uid = new_uid();
    check(seg_->getDimensions().addDimensionIndex(DCM_ReferencedSegmentNumber, dim_uid.c_str(),
                                                  DCM_SegmentIdentificationSequence, "ReferencedSegmentNumber"),
          file_, "dimension");
    check(seg_->getDimensions().addDimensionIndex(DCM_ImagePositionPatient, dim_uid.c_str(), DCM_PlanePositionSequence,
                                                  "ImagePositionPatient"),
          file_, "dimension");
  }

  // One frame per mask slice holding lumen, on the source slice at the same position.
  void add_frames() {
    const auto size = mask_->GetLargestPossibleRegion().GetSize();
    const std::size_t plane = size[0] * size[1];
    std::vector<Uint8> pixels(plane);
    for (unsigned k = 0; k < size[2]; ++k) {
      const unsigned char* first = mask_->GetBufferPointer() + std::size_t(k) * plane;
      bool any = false;
      for (std::size_t i = 0; i < plane; ++i) {
        pixels[i] = first[i] ? 1 : 0;
        any = any || pixels[i];
      }
      if (!any) continue;
      MaskImage::PointType p;
      mask_->TransformIndexToPhysicalPoint(MaskImage::IndexType{{0, 0, itk::IndexValueType(k)}}, p);
      const double along = p[0] * src_.normal[0] + p[1] * src_.normal[1] + p[2] * src_.normal[2];
      const SourceSlice* slice = src_.slice_at(along);
      if (!slice)
        throw Error(file_.string() + ": mask slice " + std::to_string(k) + " lies on no slice of the source series");
      add_frame(pixels, *slice, ++frames_);
    }
    if (frames_ == 0) throw Error(file_.string() + ": the lumen mask is empty: no segmentation to write");
  }

  void add_frame(std::vector<Uint8>& pixels, const SourceSlice& slice, Uint32 position_index) {
    const auto& q = slice.position;
    std::unique_ptr<FGPlanePosPatient> pos(
        FGPlanePosPatient::createMinimal(ds_text(q[0]).c_str(), ds_text(q[1]).c_str(), ds_text(q[2]).c_str()));
    FGFrameContent content;
    content.setDimensionIndexValues(segment_number_, 0);
    content.setDimensionIndexValues(position_index, 1);
    ImageSOPInstanceReferenceMacro* ref = nullptr;
    check(ImageSOPInstanceReferenceMacro::create(slice.sop_class_uid.c_str(), slice.sop_instance_uid.c_str(), ref),
          file_, "source reference");
    OFVector<ImageSOPInstanceReferenceMacro> refs;
    refs.push_back(*ref);
    delete ref;
    std::unique_ptr<FGDerivationImage> derivation(DcmSegmentation::createDerivationImageFG(refs, "Lumen segmentation"));
    OFVector<FGBase*> per_frame;
    per_frame.push_back(pos.get());
    per_frame.push_back(&content);
    per_frame.push_back(derivation.get());
    check(seg_->addFrame(pixels.data(), segment_number_, per_frame), file_, "frame");
    referenced_.push_back(&slice);
  }

  // Common Instance Reference: the source series and every image a frame derives from.
  void add_references() {
    IODReferences refs;
    for (const SourceSlice* s : referenced_)
      refs.add(new IODImageReference(src_.patient_id.c_str(), src_.study_uid.c_str(), src_.series_uid.c_str(),
                                     s->sop_instance_uid.c_str(), s->sop_class_uid.c_str()));
    seg_->getCommonInstanceReference().addReferences(refs, src_.study_uid.c_str());
  }

  std::string save() {
    DcmFileFormat ff;
    check(seg_->writeDataset(*ff.getDataset()), file_, "encode");
    return dicom::save_atomically(ff, file_);
  }

  const MaskImage* mask_;
  const SourceSeries& src_;
  fs::path file_;
  std::unique_ptr<DcmSegmentation> seg_;
  Uint16 segment_number_ = 0;
  Uint32 frames_ = 0;
  std::vector<const SourceSlice*> referenced_;
};

}  // namespace

std::string write_lumen_seg(const MaskImage* mask, const SourceSeries& src, const fs::path& file, int series_number) {
  dicom::quiet_dcmtk();
  if (!mask) throw Error(file.string() + ": no lumen mask");
  return SegBuilder(mask, src, file).build(series_number);
}

}  // namespace cf
