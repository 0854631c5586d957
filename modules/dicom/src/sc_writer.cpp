// An RGB picture (the flat colon image) as a DICOM Secondary Capture image in the source study.
#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcuid.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>

#include <ctime>

#include "colonflat/core/error.h"
#include "colonflat/dicom/results.h"
#include "dicom_common.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// Patient and study of the source; a new series and instance; the date and time of now.
void put_identity(DcmDataset& ds, const SourceSeries& src, int series_number, const std::string& description) {
  char date[16], time[16];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y%m%d", std::localtime(&now));
  std::strftime(time, sizeof time, "%H%M%S", std::localtime(&now));
  const std::pair<DcmTagKey, std::string> values[] = {
      {DCM_SOPClassUID, UID_SecondaryCaptureImageStorage},
      {DCM_SOPInstanceUID, new_uid()},
      {DCM_PatientID, src.patient_id},
      {DCM_PatientName, src.patient_name},
      {DCM_PatientBirthDate, src.patient_birth_date},
      {DCM_PatientSex, src.patient_sex},
      {DCM_StudyInstanceUID, src.study_uid},
      {DCM_StudyID, src.study_id},
      {DCM_StudyDate, src.study_date},
      {DCM_StudyTime, src.study_time},
      {DCM_AccessionNumber, src.accession_number},
      {DCM_ReferringPhysicianName, src.referring_physician},
      {DCM_SeriesInstanceUID, new_uid()},
      {DCM_SeriesNumber, std::to_string(series_number)},
      {DCM_SeriesDescription, description},
      {DCM_Modality, "OT"},
      {DCM_ConversionType, "WSD"},  // workstation: a derived picture, not a digitised film
      {DCM_Manufacturer, "ColonFlat"},
      {DCM_InstanceNumber, "1"},
      {DCM_ContentDate, date},
      {DCM_ContentTime, time},
      {DCM_ImageType, "DERIVED\\SECONDARY"},
      {DCM_PatientOrientation, ""},
      {DCM_Laterality, ""},  // General Series type 2C: no paired organ
      {DCM_BurnedInAnnotation, "YES"},  // labels and scale bar are drawn into the picture
  };
  for (const auto& [tag, value] : values) ds.putAndInsertString(tag, value.c_str());
}

// The pixels, top row first (VTK counts rows from the bottom), RGB interleaved.
void put_pixels(DcmDataset& ds, vtkImageData* image, const fs::path& file) {
  int dims[3];
  image->GetDimensions(dims);
  const int comps = image->GetNumberOfScalarComponents();
  if (image->GetScalarType() != VTK_UNSIGNED_CHAR || comps < 3 || dims[0] < 1 || dims[1] < 1 || dims[0] > 65535 ||
      dims[1] > 65535)
    throw Error(file.string() + ": the picture is not an 8-bit RGB image");
  const auto* src = static_cast<const unsigned char*>(image->GetScalarPointer());
  std::vector<Uint8> rgb(std::size_t(dims[0]) * dims[1] * 3);
  for (int r = 0; r < dims[1]; ++r)
    for (int c = 0; c < dims[0]; ++c)
      for (int k = 0; k < 3; ++k)
        rgb[(std::size_t(r) * dims[0] + c) * 3 + k] = src[(std::size_t(dims[1] - 1 - r) * dims[0] + c) * comps + k];
  ds.putAndInsertUint16(DCM_SamplesPerPixel, 3);
  ds.putAndInsertString(DCM_PhotometricInterpretation, "RGB");
  ds.putAndInsertUint16(DCM_PlanarConfiguration, 0);
  ds.putAndInsertUint16(DCM_Rows, Uint16(dims[1]));
  ds.putAndInsertUint16(DCM_Columns, Uint16(dims[0]));
  ds.putAndInsertUint16(DCM_BitsAllocated, 8);
  ds.putAndInsertUint16(DCM_BitsStored, 8);
  ds.putAndInsertUint16(DCM_HighBit, 7);
  ds.putAndInsertUint16(DCM_PixelRepresentation, 0);
  ds.putAndInsertUint8Array(DCM_PixelData, rgb.data(), rgb.size());
}

}  // namespace

std::string write_secondary_capture(vtkImageData* image, const SourceSeries& src, const fs::path& file,
                                    const std::string& description, int series_number) {
  dicom::quiet_dcmtk();
  if (!image) throw Error(file.string() + ": no picture");
  DcmFileFormat ff;
  DcmDataset& ds = *ff.getDataset();
  put_identity(ds, src, series_number, description);
  put_pixels(ds, image, file);
  return dicom::save_atomically(ff, file);
}

}  // namespace cf
