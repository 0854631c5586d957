// The DICOM series written by write_dicom_series read by DCMTK (an implementation independent of
// GDCM/ITK): valid files, CT Image Storage, geometry tags, and HU after DCMTK's modality transform.
#include <gtest/gtest.h>

#include <dcmtk/dcmdata/dctk.h>
#include <dcmtk/dcmimgle/dcmimage.h>

#include <cmath>
#include <filesystem>

#include "colonflat/testing/temp_dir.h"
#include "colonflat/volume/volume_io.h"

namespace cf {
namespace {

// Every slice loads in DCMTK with the expected tags, and its pixels (modality LUT applied) are the HU.
TEST(VolumeIoDicomDcmtk, WrittenSeriesReadByDcmtk) {
  testing::TempDir tmp;
  auto im = CtImage::New();
  im->SetRegions(CtImage::SizeType{{12, 10, 5}});
  const double sp[3] = {0.7, 0.7, 1.25};
  const double org[3] = {-178.85, -100.5, -20};
  im->SetSpacing(sp);
  im->SetOrigin(org);
  im->Allocate();
  for (unsigned k = 0; k < 5; ++k)
    for (unsigned j = 0; j < 10; ++j)
      for (unsigned i = 0; i < 12; ++i) im->SetPixel({{i, j, k}}, float(-1000 + 37 * int(i) + 11 * int(j) + 300 * int(k)));
  write_dicom_series(im, tmp / "s");

  for (unsigned k = 0; k < 5; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "IM%05u.dcm", k + 1);
    const std::string f = (tmp / "s" / name).string();
    DcmFileFormat ff;
    ASSERT_TRUE(ff.loadFile(f.c_str()).good()) << f;
    DcmDataset* ds = ff.getDataset();
    OFString v;
    ASSERT_TRUE(ds->findAndGetOFString(DCM_Modality, v).good());
    EXPECT_EQ(std::string(v.c_str()), "CT");
    ASSERT_TRUE(ds->findAndGetOFString(DCM_SOPClassUID, v).good());
    EXPECT_EQ(std::string(v.c_str()), UID_CTImageStorage);
    Uint16 rows = 0, cols = 0;
    ds->findAndGetUint16(DCM_Rows, rows);
    ds->findAndGetUint16(DCM_Columns, cols);
    EXPECT_EQ(rows, 10);
    EXPECT_EQ(cols, 12);
    Float64 x = 0, y = 0, z = 0, rs = 0, cs = 0;
    ds->findAndGetFloat64(DCM_ImagePositionPatient, x, 0);
    ds->findAndGetFloat64(DCM_ImagePositionPatient, y, 1);
    ds->findAndGetFloat64(DCM_ImagePositionPatient, z, 2);
    EXPECT_NEAR(x, -178.85, 1e-6);
    EXPECT_NEAR(y, -100.5, 1e-6);
    EXPECT_NEAR(z, -20 + 1.25 * k, 1e-6);
    ds->findAndGetFloat64(DCM_PixelSpacing, rs, 0);
    ds->findAndGetFloat64(DCM_PixelSpacing, cs, 1);
    EXPECT_NEAR(rs, 0.7, 1e-9);
    EXPECT_NEAR(cs, 0.7, 1e-9);
    DicomImage di(f.c_str());
    ASSERT_EQ(di.getStatus(), EIS_Normal) << DicomImage::getString(di.getStatus());
    const DiPixel* px = di.getInterData();
    ASSERT_NE(px, nullptr);
    ASSERT_EQ(px->getCount(), 120u);
    for (unsigned j = 0; j < 10; ++j)
      for (unsigned i = 0; i < 12; ++i) {
        double hu = 0;
        const void* d = px->getData();
        switch (px->getRepresentation()) {
          case EPR_Sint16: hu = static_cast<const Sint16*>(d)[j * 12 + i]; break;
          case EPR_Sint32: hu = static_cast<const Sint32*>(d)[j * 12 + i]; break;
          case EPR_Uint16: hu = static_cast<const Uint16*>(d)[j * 12 + i]; break;
          default: FAIL() << "unexpected representation";
        }
        ASSERT_EQ(hu, -1000 + 37 * int(i) + 11 * int(j) + 300 * int(k)) << i << " " << j << " " << k;
      }
  }
}

}  // namespace
}  // namespace cf
