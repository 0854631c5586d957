// Volume input/output: formats, geometry (LPS, direction), DICOM series handling, bad input, and
// the real CT in ../shared/ct/.
#include <gtest/gtest.h>
#include <itkImageFileReader.h>
#include <itkMetaDataObject.h>
#include <itkMetaImageIO.h>
#include <itkNrrdImageIO.h>
#include <malloc.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "colonflat/core/error.h"
#include "colonflat/core/malloc_tunables.h"
#include "colonflat/testing/resident_memory.h"
#include "colonflat/testing/errors.h"
#include "colonflat/testing/temp_dir.h"
#include "colonflat/volume/volume_io.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

const fs::path kShared = fs::path(COLONFLAT_SHARED_DIR) / "ct";

// A small CT-like volume with a non-trivial geometry: value = 10 i - 3 j + 100 k - 1000.
CtImage::Pointer make_ct(unsigned nx = 7, unsigned ny = 5, unsigned nz = 4, bool oblique = true) {
  auto im = CtImage::New();
  CtImage::SizeType sz{{nx, ny, nz}};
  im->SetRegions(sz);
  const double sp[3] = {0.75, 0.8, 2.5};
  const double org[3] = {-120.5, 35.25, -310};
  im->SetSpacing(sp);
  im->SetOrigin(org);
  if (oblique) {
    // A rotation by 30 degrees about z (a gantry-tilt-free oblique acquisition).
    CtImage::DirectionType dir;
    dir.SetIdentity();
    const double c = std::sqrt(3.0) / 2, s = 0.5;
    dir[0][0] = c;
    dir[0][1] = -s;
    dir[1][0] = s;
    dir[1][1] = c;
    im->SetDirection(dir);
  }
  im->Allocate();
  for (unsigned k = 0; k < nz; ++k)
    for (unsigned j = 0; j < ny; ++j)
      for (unsigned i = 0; i < nx; ++i)
        im->SetPixel({{i, j, k}}, float(10.0 * i - 3.0 * j + 100.0 * k - 1000.0));
  return im;
}

void expect_same_geometry(const itk::ImageBase<3>* a, const itk::ImageBase<3>* b, double tol = 1e-6) {
  ASSERT_EQ(a->GetLargestPossibleRegion().GetSize(), b->GetLargestPossibleRegion().GetSize());
  for (int d = 0; d < 3; ++d) {
    EXPECT_NEAR(a->GetSpacing()[d], b->GetSpacing()[d], tol) << "spacing " << d;
    EXPECT_NEAR(a->GetOrigin()[d], b->GetOrigin()[d], tol) << "origin " << d;
    for (int e = 0; e < 3; ++e) EXPECT_NEAR(a->GetDirection()[d][e], b->GetDirection()[d][e], tol) << "direction " << d << e;
  }
}

void expect_same_values(const CtImage* a, const CtImage* b) {
  const std::size_t n = a->GetLargestPossibleRegion().GetNumberOfPixels();
  ASSERT_EQ(n, b->GetLargestPossibleRegion().GetNumberOfPixels());
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(a->GetBufferPointer()[i], b->GetBufferPointer()[i]) << "voxel " << i;
}

using testing::error_of;

// Each written format reads back with the same HU values and the same LPS geometry (oblique direction).
TEST(VolumeIoFormats, RoundTripKeepsValuesAndGeometry) {
  testing::TempDir tmp;
  auto ct = make_ct();
  for (const std::string name : {"ct.nrrd", "ct.nii.gz", "ct.nii", "ct.mha"}) {
    SCOPED_TRACE(name);
    write_ct_volume(ct, tmp / name);
    auto back = read_ct_volume(tmp / name);
    expect_same_geometry(ct, back, 1e-5);
    expect_same_values(ct, back);
  }
  // No temporary file is left behind.
  for (const auto& e : fs::directory_iterator(tmp.path())) EXPECT_NE(e.path().filename().string()[0], '.');
}

// CT is stored as int16 HU: values are rounded and clamped.
TEST(VolumeIoFormats, CtIsStoredAsRoundedInt16) {
  testing::TempDir tmp;
  auto ct = make_ct(3, 3, 3, false);
  ct->SetPixel({{0, 0, 0}}, 12.6f);
  ct->SetPixel({{1, 0, 0}}, 1e6f);
  write_ct_volume(ct, tmp / "c.nrrd");
  auto back = read_ct_volume(tmp / "c.nrrd");
  EXPECT_EQ(back->GetPixel({{0, 0, 0}}), 13.f);
  EXPECT_EQ(back->GetPixel({{1, 0, 0}}), 32767.f);
}

// A 16-bit NRRD or MetaImage CT (read as stored, converted on the threads) reads as ITK's own float
// read gives it: every voxel, the geometry of an oblique volume and the header dictionary.
TEST(VolumeIoFormats, SixteenBitFilesReadAsItksFloatRead) {
  testing::TempDir tmp;
  auto ct = make_ct(33, 21, 17);
  ct->SetPixel({{4, 5, 6}}, -1024.f);
  ct->SetPixel({{32, 20, 16}}, 3071.f);
  itk::EncapsulateMetaData<std::string>(ct->GetMetaDataDictionary(), "0018|5100", "FFS");
  for (const char* name : {"c.nrrd", "c.mha"}) {
    write_ct_volume(ct, tmp / name);
    const auto ours = read_ct_volume(tmp / name);
    auto itk_read = itk::ImageFileReader<CtImage>::New();
    if (std::string(name) == "c.nrrd") itk_read->SetImageIO(itk::NrrdImageIO::New());
    else itk_read->SetImageIO(itk::MetaImageIO::New());
    itk_read->SetFileName((tmp / name).string());
    itk_read->Update();
    const CtImage* want = itk_read->GetOutput();
    expect_same_geometry(ours, want, 0.0);
    const std::size_t n = want->GetLargestPossibleRegion().GetNumberOfPixels();
    std::size_t differ = 0;
    for (std::size_t i = 0; i < n; ++i) differ += ours->GetBufferPointer()[i] != want->GetBufferPointer()[i];
    EXPECT_EQ(differ, 0u) << name;
    EXPECT_EQ(ours->GetPixel({{32, 20, 16}}), 3071.f) << name;
    EXPECT_EQ(ours->GetMetaDataDictionary().GetKeys(), want->GetMetaDataDictionary().GetKeys()) << name;
  }
}

// With the heap keeping what is freed (ColonFlat's malloc settings, set here with mallopt), reading
// a 16-bit CT holds only the float image: the reader's 16-bit buffer (32 MiB here) is given back,
// and a mask read holds only its bytes, not the float copy it was converted from (64 MiB).
TEST(VolumeIoMemory, ReadersGiveTheirConversionBuffersBack) {
  testing::TempDir tmp;
  const unsigned n = 256;  // 16.8 M voxels: 64 MiB as float, 32 MiB as int16, 16 MiB as bytes
  {
    auto ct = make_ct(n, n, n, false);
    write_ct_volume(ct, tmp / "ct.nrrd");
    auto m = MaskImage::New();
    m->CopyInformation(ct);
    m->SetRegions(ct->GetLargestPossibleRegion());
    m->Allocate(true);
    write_mask(m, tmp / "mask.nrrd");
  }
  ASSERT_EQ(mallopt(M_MMAP_THRESHOLD, 1 << 30), 1);
  ASSERT_EQ(mallopt(M_TRIM_THRESHOLD, 1 << 30), 1);
  release_free_memory();
  const double before = testing::resident_mib();
  auto ct = read_ct_volume(tmp / "ct.nrrd");
  const double with_ct = testing::resident_mib();
  auto mask = read_mask(tmp / "mask.nrrd");
  const double with_mask = testing::resident_mib();
  mallopt(M_TRIM_THRESHOLD, 128 * 1024);  // glibc's defaults again (the adaptive threshold stays off)
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
  EXPECT_LT(with_ct - before, 64.0 + 12.0) << "the CT read holds more than its float image";
  EXPECT_LT(with_mask - with_ct, 16.0 + 12.0) << "the mask read holds more than its bytes";
  EXPECT_EQ(ct->GetPixel({{n - 1, n - 1, n - 1}}), std::round(10.f * (n - 1) - 3.f * (n - 1) + 100.f * (n - 1) - 1000.f));
}

// A label volume (small non-negative integers) reads as 0/1, a CT read as a mask is refused (issue
// 14: reconstruct must not turn a CT into a box), and masks round-trip through every written format.
TEST(VolumeIoFormats, MaskRoundTripAndBinarisation) {
  testing::TempDir tmp;
  auto ct = make_ct(6, 5, 4);
  write_ct_volume(ct, tmp / "values.nrrd");  // HU values: not a mask
  EXPECT_THROW(read_mask(tmp / "values.nrrd"), InputError);
  auto labels = MaskImage::New();
  labels->CopyInformation(ct);
  labels->SetRegions(ct->GetLargestPossibleRegion());
  labels->Allocate();
  for (std::size_t i = 0; i < labels->GetLargestPossibleRegion().GetNumberOfPixels(); ++i)
    labels->GetBufferPointer()[i] = static_cast<unsigned char>(i % 4 == 0 ? 0 : i % 3 + 1);  // labels 0..3
  write_mask(labels, tmp / "labels.nrrd");
  auto m = read_mask(tmp / "labels.nrrd");
  std::size_t ones = 0;
  for (std::size_t i = 0; i < m->GetLargestPossibleRegion().GetNumberOfPixels(); ++i) {
    EXPECT_EQ(m->GetBufferPointer()[i], labels->GetBufferPointer()[i] != 0 ? 1 : 0);
    ones += m->GetBufferPointer()[i];
  }
  EXPECT_GT(ones, 0u);
  for (const std::string name : {"m.nrrd", "m.nii.gz", "m.mha"}) {
    write_mask(m, tmp / name);
    auto b = read_mask(tmp / name);
    expect_same_geometry(m, b, 1e-5);
    EXPECT_EQ(0, std::memcmp(m->GetBufferPointer(), b->GetBufferPointer(), m->GetLargestPossibleRegion().GetNumberOfPixels()));
  }
}

// Unsupported output formats are usage errors and write nothing.
TEST(VolumeIoFormats, RefusesUnsupportedOutput) {
  testing::TempDir tmp;
  auto ct = make_ct(3, 3, 3);
  EXPECT_THROW(write_ct_volume(ct, tmp / "ct.png"), UsageError);
  EXPECT_THROW(write_ct_volume(ct, tmp / "ct.mhd"), UsageError);
  EXPECT_TRUE(fs::is_empty(tmp.path()));
}

// Missing, unknown, truncated and empty-folder inputs: InputError naming the file and the problem
// (for a truncated NRRD: the reason, without ITK's decoration).
TEST(VolumeIoBadInput, ClearErrors) {
  testing::TempDir tmp;
  EXPECT_EQ(error_of([&] { read_ct_volume(tmp / "none.nrrd"); }), (tmp / "none.nrrd").string() + ": no such file");
  std::ofstream(tmp / "x.txt") << "hello";
  EXPECT_NE(error_of([&] { read_ct_volume(tmp / "x.txt"); }).find("unknown volume format"), std::string::npos);
  write_ct_volume(make_ct(20, 20, 20), tmp / "full.nrrd");
  {
    // Truncate the data part.
    std::ifstream in(tmp / "full.nrrd", std::ios::binary);
    std::string all((std::istreambuf_iterator<char>(in)), {});
    std::ofstream(tmp / "cut.nrrd", std::ios::binary) << all.substr(0, all.size() / 2);
  }
  const std::string e = error_of([&] { read_ct_volume(tmp / "cut.nrrd"); });
  EXPECT_EQ(e.rfind((tmp / "cut.nrrd").string() + ": ", 0), 0u) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  EXPECT_NE(e.find("truncated or corrupt"), std::string::npos) << e;  // a reason, not ITK's bare "Error reading"
  EXPECT_EQ(e.find("0x"), std::string::npos) << e;                    // no object addresses
  fs::create_directories(tmp / "empty");
  EXPECT_NE(error_of([&] { read_ct_volume(tmp / "empty"); }).find("no readable DICOM"), std::string::npos);
  try {
    read_ct_volume(tmp / "none.nrrd");
  } catch (const Error& err) {
    EXPECT_EQ(err.exit_code(), kExitBadInput);
  }
}

// A DICOM series written here reads back (sorted by position) with the same values and geometry.
TEST(VolumeIoDicom, SeriesRoundTrip) {
  testing::TempDir tmp;
  auto ct = make_ct(16, 12, 9);
  write_dicom_series(ct, tmp / "series");
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(tmp / "series")) files += e.path().extension() == ".dcm";
  EXPECT_EQ(files, 9u);
  auto back = read_ct_volume(tmp / "series");
  expect_same_geometry(ct, back, 1e-5);
  expect_same_values(ct, back);
  const auto list = list_dicom_series(tmp / "series");
  ASSERT_EQ(list.size(), 1u);
  EXPECT_EQ(list[0].modality, "CT");
  EXPECT_EQ(list[0].files, 9u);
}

// Slices are ordered by position, not by file name.
TEST(VolumeIoDicom, SortsByPositionNotName) {
  testing::TempDir tmp;
  auto ct = make_ct(8, 8, 6, false);
  write_dicom_series(ct, tmp / "s");
  // Reverse the file names.
  std::vector<fs::path> names;
  for (const auto& e : fs::directory_iterator(tmp / "s")) names.push_back(e.path());
  std::sort(names.begin(), names.end());
  for (std::size_t i = 0; i < names.size(); ++i) fs::rename(names[i], tmp / "s" / ("tmp" + std::to_string(i)));
  for (std::size_t i = 0; i < names.size(); ++i)
    fs::rename(tmp / "s" / ("tmp" + std::to_string(i)), tmp / "s" / ("Z" + std::to_string(names.size() - i) + ".dcm"));
  auto back = read_ct_volume(tmp / "s");
  expect_same_values(ct, back);
}

// A missing slice is detected and reported with the gap; nothing is read.
TEST(VolumeIoDicom, MissingSliceIsReported) {
  testing::TempDir tmp;
  write_dicom_series(make_ct(8, 8, 10, false), tmp / "s");
  fs::remove(tmp / "s" / "IM00005.dcm");
  const std::string e = error_of([&] { read_ct_volume(tmp / "s"); });
  EXPECT_NE(e.find("uneven slice spacing: gap of 5 mm between IM00004.dcm and IM00006.dcm"), std::string::npos) << e;
  EXPECT_NE(e.find("1 missing slice"), std::string::npos) << e;
}

// Several series in one folder are listed; one is chosen by UID (option or DIR/UID path).
TEST(VolumeIoDicom, SeveralSeriesListedAndChosen) {
  testing::TempDir tmp;
  auto a = make_ct(8, 8, 4, false), b = make_ct(8, 8, 3, true);
  DicomWriteOptions oa, ob;
  oa.uid_seed = 1;
  ob.uid_seed = 2;
  write_dicom_series(a, tmp / "a", oa);
  write_dicom_series(b, tmp / "b", ob);
  fs::create_directories(tmp / "both");
  for (const auto& e : fs::directory_iterator(tmp / "a")) fs::rename(e.path(), tmp / "both" / ("a" + e.path().filename().string()));
  for (const auto& e : fs::directory_iterator(tmp / "b")) fs::rename(e.path(), tmp / "both" / ("b" + e.path().filename().string()));
  const auto list = list_dicom_series(tmp / "both");
  ASSERT_EQ(list.size(), 2u);
  const std::string uid_a = derived_uid(1, "series"), uid_b = derived_uid(2, "series");
  const std::string e = error_of([&] { read_ct_volume(tmp / "both"); });
  EXPECT_NE(e.find("2 DICOM series"), std::string::npos) << e;
  EXPECT_NE(e.find(uid_a), std::string::npos) << e;
  EXPECT_NE(e.find(uid_b), std::string::npos) << e;
  VolumeReadOptions o;
  o.series_uid = uid_b;
  auto rb = read_ct_volume(tmp / "both", o);
  expect_same_geometry(b, rb, 1e-5);
  expect_same_values(b, rb);
  auto ra = read_ct_volume(tmp / "both" / uid_a);
  expect_same_values(a, ra);
  EXPECT_NE(error_of([&] { read_ct_volume(tmp / "both" / "1.2.3"); }).find("no DICOM series 1.2.3"), std::string::npos);
  // The info lists both series without reading a volume.
  std::ostringstream out;
  ASSERT_TRUE(try_volume_info((tmp / "both").string(), true, out));
  auto j = nlohmann::json::parse(out.str());
  EXPECT_EQ(j["series"].size(), 2u);
  EXPECT_FALSE(j.contains("size"));
  // With a chosen series, the info reads that volume.
  std::ostringstream chosen;
  ASSERT_TRUE(try_volume_info((tmp / "both").string(), true, chosen, uid_a));
  auto ja = nlohmann::json::parse(chosen.str());
  EXPECT_EQ(ja["series_uid"], uid_a);
  EXPECT_EQ(ja["size"][2], 4);
}

// A truncated slice file in a series: one-line InputError naming the folder; nothing returned.
TEST(VolumeIoDicom, TruncatedSliceIsReported) {
  testing::TempDir tmp;
  write_dicom_series(make_ct(32, 32, 6, false), tmp / "s");
  const fs::path f = tmp / "s" / "IM00003.dcm";
  const auto size = fs::file_size(f);
  fs::resize_file(f, size - 1000);
  const std::string e = error_of([&] { read_ct_volume(tmp / "s"); });
  EXPECT_EQ(e.rfind((tmp / "s").string() + ": ", 0), 0u) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

// The derived UIDs are valid DICOM UIDs (digits and dots, at most 64 characters) and deterministic.
TEST(VolumeIoDicom, DerivedUids) {
  const std::string u = derived_uid(7, "series");
  EXPECT_EQ(u, derived_uid(7, "series"));
  EXPECT_NE(u, derived_uid(8, "series"));
  EXPECT_LE(u.size(), 64u);
  EXPECT_EQ(u.find_first_not_of("0123456789."), std::string::npos);
  EXPECT_EQ(u.rfind("2.25.", 0), 0u);
}

// Real CT: the single-file NRRD and the detached-header NRRD (93 raw slices) give the same volume.
TEST(VolumeIoShared, HeadCtAttachedAndDetachedNrrd) {
  const fs::path dir = kShared / "vtk_headsq_quarter_ct_head";
  if (!fs::exists(dir)) GTEST_SKIP() << "shared data not available";
  auto a = read_ct_volume(dir / "headsq_quarter.nrrd");
  auto b = read_ct_volume(dir / "slices" / "quarter.nhdr");
  const auto sz = a->GetLargestPossibleRegion().GetSize();
  EXPECT_EQ(sz[0], 64u);
  EXPECT_EQ(sz[1], 64u);
  EXPECT_EQ(sz[2], 93u);
  EXPECT_NEAR(a->GetSpacing()[0], 3.2, 1e-9);
  EXPECT_NEAR(a->GetSpacing()[2], 1.5, 1e-9);
  ASSERT_EQ(b->GetLargestPossibleRegion().GetSize(), sz);
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(b->GetSpacing()[d], a->GetSpacing()[d], 1e-9);
  expect_same_values(a, b);
  // Scanner units (about HU + 1024): 0 .. 3926 per the data's README.
  float lo = 1e9f, hi = -1e9f;
  for (std::size_t i = 0; i < a->GetLargestPossibleRegion().GetNumberOfPixels(); ++i) {
    lo = std::min(lo, a->GetBufferPointer()[i]);
    hi = std::max(hi, a->GetBufferPointer()[i]);
  }
  EXPECT_EQ(lo, 0.f);
  EXPECT_EQ(hi, 3926.f);
  // Info flags the missing negative values.
  std::ostringstream out;
  ASSERT_TRUE(try_volume_info((dir / "headsq_quarter.nrrd").string(), false, out));
  EXPECT_NE(out.str().find("64 x 64 x 93"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("HU + 1024"), std::string::npos) << out.str();
}

// Real single DICOM CT slices: rescale slope/intercept applied (HU), pixel spacing read.
TEST(VolumeIoShared, SingleDicomSlices) {
  const fs::path dir = kShared / "dicom_ct_single_slices";
  if (!fs::exists(dir)) GTEST_SKIP() << "shared data not available";
  struct Case {
    const char* file;
    unsigned n;
    double spacing;
  };
  for (const Case& c : {Case{"CT_small.dcm", 128, 0.661468}, Case{"693_UNCI.dcm", 512, 0.478516},
                        Case{"dicompyler-ct.0.dcm", 512, 1.074219}}) {
    SCOPED_TRACE(c.file);
    auto im = read_ct_volume(dir / c.file);
    const auto sz = im->GetLargestPossibleRegion().GetSize();
    EXPECT_EQ(sz[0], c.n);
    EXPECT_EQ(sz[1], c.n);
    EXPECT_EQ(sz[2], 1u);
    EXPECT_NEAR(im->GetSpacing()[0], c.spacing, 1e-5);
    float lo = 1e9f;
    for (std::size_t i = 0; i < im->GetLargestPossibleRegion().GetNumberOfPixels(); ++i) lo = std::min(lo, im->GetBufferPointer()[i]);
    EXPECT_LT(lo, -500.f) << "air should be negative HU after the rescale";
    // The same file as a one-file series folder (the series checks accept it) gives the same volume.
    testing::TempDir tmp;
    fs::create_directories(tmp / "one");
    fs::copy_file(dir / c.file, tmp / "one" / c.file);
    auto as_series = read_ct_volume(tmp / "one");
    expect_same_values(im, as_series);
  }
}

// The enhanced multi-frame CT is refused with a clear message (file and folder forms).
TEST(VolumeIoShared, EnhancedMultiFrameRefused) {
  const fs::path f = kShared / "dicom_ct_single_slices" / "eCT_Supplemental.dcm";
  if (!fs::exists(f)) GTEST_SKIP() << "shared data not available";
  const std::string e = error_of([&] { read_ct_volume(f); });
  EXPECT_NE(e.find("enhanced multi-frame CT"), std::string::npos) << e;
  EXPECT_EQ(e.rfind(f.string() + ": ", 0), 0u) << e;
  testing::TempDir tmp;
  fs::create_directories(tmp / "d");
  fs::copy_file(f, tmp / "d" / "e.dcm");
  const std::string e2 = error_of([&] { read_ct_volume(tmp / "d"); });
  EXPECT_NE(e2.find("enhanced multi-frame CT"), std::string::npos) << e2;
}

// A folder of single slices from different series lists every series and asks for a choice.
TEST(VolumeIoShared, FolderOfUnrelatedSlices) {
  const fs::path dir = kShared / "dicom_ct_single_slices";
  if (!fs::exists(dir)) GTEST_SKIP() << "shared data not available";
  const auto list = list_dicom_series(dir);
  EXPECT_GE(list.size(), 3u);
  const std::string e = error_of([&] { read_ct_volume(dir); });
  EXPECT_NE(e.find("DICOM series"), std::string::npos) << e;
}

// try_volume_info: false (nothing printed) for a non-volume; text and JSON for a volume.
TEST(VolumeIoInfo, TryVolumeInfo) {
  testing::TempDir tmp;
  std::ostringstream none;
  EXPECT_FALSE(try_volume_info((tmp / "mesh.vtp").string(), false, none));
  EXPECT_TRUE(none.str().empty());
  write_ct_volume(make_ct(), tmp / "ct.nrrd");
  std::ostringstream txt, js;
  ASSERT_TRUE(try_volume_info((tmp / "ct.nrrd").string(), false, txt));
  EXPECT_NE(txt.str().find("7 x 5 x 4 voxels"), std::string::npos) << txt.str();
  EXPECT_NE(txt.str().find("spacing         [0.75, 0.8, 2.5] mm"), std::string::npos) << txt.str();
  ASSERT_TRUE(try_volume_info((tmp / "ct.nrrd").string(), true, js));
  auto j = nlohmann::json::parse(js.str());
  EXPECT_EQ(j["hu_range"][0], -1000.0 + 0 - 12);  // i = 0, j = 4, k = 0
  EXPECT_EQ(j["hu_range"][1], -1000.0 + 60 + 300);
  EXPECT_NEAR(j["direction"][1][0].get<double>(), 0.5, 1e-6);
  EXPECT_THROW(try_volume_info((tmp / "gone.nrrd").string(), false, txt), InputError);
}

// The artifacts write through a temporary path (as the pipeline does), also for .nii.gz.
TEST(VolumeIoArtifacts, WriteThroughTemporaryPath) {
  testing::TempDir tmp;
  auto ct = make_ct();
  const fs::path target = tmp / "ct.nii.gz", t = tmp / ".ct.nii.tmp-1-0.gz";
  volume_artifact().write(std::any(ct), t, target);
  fs::rename(t, target);
  auto back = std::any_cast<CtImage::Pointer>(volume_artifact().read(target));
  expect_same_values(ct, back);
  EXPECT_EQ(volume_artifact().name, "volume");
  EXPECT_EQ(mask_artifact().name, "mask");
}

}  // namespace
}  // namespace cf
