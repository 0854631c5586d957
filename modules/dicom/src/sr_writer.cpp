// The polyp candidates as a Comprehensive 3D SR (DCMTK dcmsr): one "Finding" container a candidate
// with its 3D point (SCOORD3D in the source's frame of reference), size, position from the rectum,
// score and supine-prone pairing.
#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmsr/dsrdoc.h>
#include <dcmtk/dcmsr/dsrnumvl.h>
#include <dcmtk/dcmsr/dsrsc3vl.h>

#include <iomanip>
#include <sstream>

#include "colonflat/core/error.h"
#include "colonflat/dicom/results.h"
#include "dicom_common.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// Concepts: DICOM (DCM), SNOMED CT (SCT), LOINC (LN) where one exists; ColonFlat's own (99CFLAT)
// where none does.
const DSRCodedEntryValue kReport("18748-4", "LN", "Diagnostic Imaging Report");
const DSRCodedEntryValue kFinding("121071", "DCM", "Finding");
const DSRCodedEntryValue kTracking("112039", "DCM", "Tracking Identifier");
const DSRCodedEntryValue kCenter("111010", "DCM", "Center");
const DSRCodedEntryValue kDiameter("81827009", "SCT", "Diameter");
const DSRCodedEntryValue kFromRectum("CF-0001", "99CFLAT", "Distance from rectum along the colon");
const DSRCodedEntryValue kScore("CF-0002", "99CFLAT", "Polyp candidate score");
const DSRCodedEntryValue kPairing("CF-0003", "99CFLAT", "Supine-prone pairing");
const DSRCodedEntryValue kMm("mm", "UCUM", "millimeter");
const DSRCodedEntryValue kCm("cm", "UCUM", "centimeter");
const DSRCodedEntryValue kNoUnits("1", "UCUM", "no units");

std::string number(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

void check(const OFCondition& c, const fs::path& file, const std::string& what) {
  if (c.bad()) throw Error(file.string() + ": cannot build the structured report (" + what + "): " + c.text());
}

// The study the report belongs to, its own new series.
void set_header(DSRDocument& doc, const SourceSeries& src, int series_number, const fs::path& file) {
  check(doc.createNewSeriesInStudy(src.study_uid.c_str()), file, "series");
  doc.setPatientID(src.patient_id.c_str(), OFFalse);
  doc.setPatientName(src.patient_name.c_str(), OFFalse);
  doc.setPatientBirthDate(src.patient_birth_date.c_str(), OFFalse);
  doc.setPatientSex(src.patient_sex.c_str(), OFFalse);
  doc.setStudyID(src.study_id.c_str(), OFFalse);
  doc.setStudyDate(src.study_date.c_str(), OFFalse);
  doc.setStudyTime(src.study_time.c_str(), OFFalse);
  doc.setAccessionNumber(src.accession_number.c_str(), OFFalse);
  doc.setReferringPhysicianName(src.referring_physician.c_str(), OFFalse);
  doc.setSeriesNumber(std::to_string(series_number).c_str());
  doc.setSeriesDescription("ColonFlat polyp candidates");
  doc.setManufacturer("ColonFlat");
}

void add_number(DSRDocument& doc, const DSRCodedEntryValue& concept, const std::string& value,
                const DSRCodedEntryValue& unit, const fs::path& file) {
  check(doc.getTree().addContentItem(DSRTypes::RT_contains, DSRTypes::VT_Num, concept), file, "numeric item");
  check(doc.getTree().getCurrentContentItem().setNumericValue(DSRNumericMeasurementValue(value.c_str(), unit)), file,
        "numeric value");
}

void add_text(DSRDocument& doc, const DSRCodedEntryValue& concept, const std::string& value, const fs::path& file) {
  check(doc.getTree().addContentItem(DSRTypes::RT_contains, DSRTypes::VT_Text, concept), file, "text item");
  check(doc.getTree().getCurrentContentItem().setStringValue(value.c_str()), file, "text value");
}

// One candidate: a Finding container holding its identifier, point, size, position and pairing.
void add_candidate(DSRDocument& doc, const SrCandidate& c, const std::string& frame, bool first,
                   const fs::path& file) {
  DSRDocumentTree& tree = doc.getTree();
  if (first) check(tree.addChildContentItem(DSRTypes::RT_contains, DSRTypes::VT_Container, kFinding), file, "finding");
  else check(tree.addContentItem(DSRTypes::RT_contains, DSRTypes::VT_Container, kFinding), file, "finding");
  tree.getCurrentContentItem().setContinuityOfContent(DSRTypes::COC_Separate);
  check(tree.addChildContentItem(DSRTypes::RT_contains, DSRTypes::VT_Text, kTracking), file, "identifier");
  check(tree.getCurrentContentItem().setStringValue(("candidate " + std::to_string(c.id)).c_str()), file, "identifier");
  check(tree.addContentItem(DSRTypes::RT_contains, DSRTypes::VT_SCoord3D, kCenter), file, "point");
  DSRSpatialCoordinates3DValue point(DSRTypes::GT3_Point);
  point.getGraphicDataList().addItem(Float32(c.lps_mm[0]), Float32(c.lps_mm[1]), Float32(c.lps_mm[2]));
  check(point.setFrameOfReferenceUID(frame.c_str()), file, "frame of reference");
  check(tree.getCurrentContentItem().setSpatialCoordinates3D(point), file, "point");
  add_number(doc, kDiameter, number(c.size_mm, 1), kMm, file);
  if (c.from_rectum_cm) add_number(doc, kFromRectum, number(*c.from_rectum_cm, 1), kCm, file);
  if (c.score) add_number(doc, kScore, number(*c.score, 3), kNoUnits, file);
  if (!c.pairing.empty()) add_text(doc, kPairing, c.pairing, file);
  tree.goUp();
}

}  // namespace

std::string write_candidates_sr(const std::vector<SrCandidate>& candidates, const SourceSeries& src,
                                const fs::path& file, int series_number) {
  dicom::quiet_dcmtk();
  DSRDocument doc(DSRTypes::DT_Comprehensive3DSR);
  set_header(doc, src, series_number, file);
  DSRDocumentTree& tree = doc.getTree();
  check(tree.addContentItem(DSRTypes::RT_isRoot, DSRTypes::VT_Container) ? EC_Normal : EC_IllegalCall, file, "root");
  check(tree.getCurrentContentItem().setConceptName(kReport), file, "root");
  for (std::size_t i = 0; i < candidates.size(); ++i)
    add_candidate(doc, candidates[i], src.frame_of_reference_uid, i == 0, file);
  if (candidates.empty()) {
    check(tree.addChildContentItem(DSRTypes::RT_contains, DSRTypes::VT_Text, kFinding), file, "no finding");
    check(tree.getCurrentContentItem().setStringValue("no polyp candidate"), file, "no finding");
  }
  DcmFileFormat ff;
  check(doc.write(*ff.getDataset()), file, "encode");
  return dicom::save_atomically(ff, file);
}

}  // namespace cf
