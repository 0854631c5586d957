#include "colonflat/testdata/mask_pair.h"

#include <itkImageRegionConstIteratorWithIndex.h>
#include <itkImageRegionIteratorWithIndex.h>
#include <itkImageDuplicator.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "colonflat/core/error.h"
#include "colonflat/core/voxel_path.h"

namespace cf {
namespace {
constexpr float kUnreached = std::numeric_limits<float>::infinity();
constexpr double kPi = 3.141592653589793;

Eigen::Vector3d physical(const MaskImage* m, const MaskImage::IndexType& i) {
  MaskImage::PointType p;
  m->TransformIndexToPhysicalPoint(i, p);
  return {p[0], p[1], p[2]};
}
}  // namespace

MaskCourse::MaskCourse(MaskImage::Pointer mask) : mask_(std::move(mask)) {
  const auto region = mask_->GetLargestPossibleRegion();
  MaskImage::IndexType lo = region.GetUpperIndex(), hi = region.GetIndex(), start{};
  double lowest = std::numeric_limits<double>::infinity();
  long n = 0;
  itk::ImageRegionConstIteratorWithIndex<MaskImage> it(mask_, region);
  for (; !it.IsAtEnd(); ++it) {
    if (!it.Get()) continue;
    const auto i = it.GetIndex();
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], i[d]), hi[d] = std::max(hi[d], i[d]);
    const Eigen::Vector3d p = physical(mask_, i);
    centroid_ += p, ++n;
    if (p.z() < lowest) lowest = p.z(), start = i;  // LPS z = superior: the rectal end is lowest
  }
  if (n == 0) throw InputError("mask", "empty mask");
  centroid_ /= double(n);
  lo_ = lo;
  for (int d = 0; d < 3; ++d) size_[d] = size_t(hi[d] - lo[d] + 1);
  const auto sp = mask_->GetSpacing();
  const auto full = mask_->GetBufferedRegion();
  const VoxelBox box{mask_->GetBufferPointer(),
                     {int(full.GetSize(0)), int(full.GetSize(1)), int(full.GetSize(2))},
                     {sp[0], sp[1], sp[2]},
                     {int(lo[0] - full.GetIndex(0)), int(lo[1] - full.GetIndex(1)), int(lo[2] - full.GetIndex(2))},
                     {int(hi[0] - full.GetIndex(0)) + 1, int(hi[1] - full.GetIndex(1)) + 1, int(hi[2] - full.GetIndex(2)) + 1}};
  path_ = voxel_path_distance(box, {int(start[0] - full.GetIndex(0)), int(start[1] - full.GetIndex(1)),
                                    int(start[2] - full.GetIndex(2))});
  for (float d : path_)
    if (d != kUnreached) length_ = std::max(length_, double(d));
}

size_t MaskCourse::box_index(const MaskImage::IndexType& i) const {
  return size_t(i[0] - lo_[0]) + size_[0] * (size_t(i[1] - lo_[1]) + size_[1] * size_t(i[2] - lo_[2]));
}

double MaskCourse::path_at(const Eigen::Vector3d& lps) const {
  MaskImage::PointType p;
  for (int d = 0; d < 3; ++d) p[d] = lps[d];
  itk::ContinuousIndex<double, 3> ci;
  mask_->TransformPhysicalPointToContinuousIndex(p, ci);
  const auto sp = mask_->GetSpacing();
  const int r[3] = {int(15 / sp[0]) + 1, int(15 / sp[1]) + 1, int(15 / sp[2]) + 1};
  double best = std::numeric_limits<double>::infinity(), path = std::nan("");
  for (long c = long(std::lround(ci[2])) - r[2]; c <= long(std::lround(ci[2])) + r[2]; ++c)
    for (long b = long(std::lround(ci[1])) - r[1]; b <= long(std::lround(ci[1])) + r[1]; ++b)
      for (long a = long(std::lround(ci[0])) - r[0]; a <= long(std::lround(ci[0])) + r[0]; ++a) {
        const MaskImage::IndexType j = {{a, b, c}};
        if (a < lo_[0] || b < lo_[1] || c < lo_[2] || a >= lo_[0] + long(size_[0]) || b >= lo_[1] + long(size_[1]) ||
            c >= lo_[2] + long(size_[2]))
          continue;
        const float v = path_[box_index(j)];
        if (v == kUnreached) continue;
        const double dist = (physical(mask_, j) - lps).squaredNorm();
        if (dist < best) best = dist, path = v;
      }
  return best <= 15.0 * 15.0 ? path : std::nan("");
}

std::vector<MaskPolyp> MaskCourse::place_polyps(int count, std::uint64_t seed) {
  std::vector<MaskImage::IndexType> wall;  // lumen voxels with a face neighbour outside the lumen
  for (size_t k = 0; k < path_.size(); ++k) {
    if (path_[k] == kUnreached) continue;
    const MaskImage::IndexType i = {{lo_[0] + long(k % size_[0]), lo_[1] + long(k / size_[0] % size_[1]),
                                     lo_[2] + long(k / (size_[0] * size_[1]))}};
    bool edge = false;
    for (int d = 0; d < 3 && !edge; ++d)
      for (int s : {-1, 1}) {
        MaskImage::IndexType j = i;
        j[d] += s;
        edge |= !mask_->GetLargestPossibleRegion().IsInside(j) || !mask_->GetPixel(j);
      }
    if (edge) wall.push_back(i);
  }
  std::mt19937_64 rng(seed);
  std::vector<MaskPolyp> out;
  const auto sp = mask_->GetSpacing();
  for (int n = 0; n < count; ++n) {
    const double target = (0.08 + 0.84 * n / std::max(1, count - 1)) * length_;
    std::vector<MaskImage::IndexType> near;
    for (const auto& i : wall)
      if (std::abs(path_[box_index(i)] - target) < 3) near.push_back(i);
    if (near.empty()) continue;
    const MaskImage::IndexType c = near[std::uniform_int_distribution<size_t>(0, near.size() - 1)(rng)];
    const double diameter = 6 + n % 5, r = diameter / 2;
    out.push_back({int(out.size()) + 1, physical(mask_, c), diameter, path_[box_index(c)]});
    const int rx = int(r / sp[0]) + 1, ry = int(r / sp[1]) + 1, rz = int(r / sp[2]) + 1;
    for (long z = c[2] - rz; z <= c[2] + rz; ++z)
      for (long y = c[1] - ry; y <= c[1] + ry; ++y)
        for (long x = c[0] - rx; x <= c[0] + rx; ++x) {
          const MaskImage::IndexType j = {{x, y, z}};
          if (!mask_->GetLargestPossibleRegion().IsInside(j) || !mask_->GetPixel(j)) continue;
          if ((physical(mask_, j) - out.back().lps).norm() > r) continue;
          mask_->SetPixel(j, 0);
          path_[box_index(j)] = kUnreached;
        }
  }
  return out;
}

Eigen::Vector3d MaskCourse::moved(const Eigen::Vector3d& p, const Eigen::Vector3d& centre, const Eigen::Vector3d& shift,
                                  double rotate_deg) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(rotate_deg * kPi / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return R * (p - centre) + centre + shift;
}

Eigen::Vector3d MaskCourse::unmoved(const Eigen::Vector3d& p, const Eigen::Vector3d& centre, const Eigen::Vector3d& shift,
                                    double rotate_deg) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(rotate_deg * kPi / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return R.transpose() * (p - centre - shift) + centre;
}

std::vector<MaskPolyp> polyps_seen(const std::vector<MaskPolyp>& polyps, const std::vector<std::pair<double, double>>& cuts) {
  std::vector<MaskPolyp> out;
  for (const auto& q : polyps) {
    bool cut = false;
    for (const auto& [a, b] : cuts) cut |= q.path_mm >= a - q.diameter_mm && q.path_mm < b + q.diameter_mm;
    if (!cut) out.push_back(q);
  }
  return out;
}

MaskImage::Pointer MaskCourse::cut_and_move(const std::vector<std::pair<double, double>>& cuts,
                                            const Eigen::Vector3d& shift, double rotate_deg) const {
  auto dup = itk::ImageDuplicator<MaskImage>::New();
  dup->SetInputImage(mask_);
  dup->Update();
  MaskImage::Pointer out = dup->GetOutput();
  for (size_t k = 0; k < path_.size(); ++k) {
    const float s = path_[k];
    if (s == kUnreached) continue;
    for (const auto& [a, b] : cuts)
      if (s >= a && s < b) {
        out->SetPixel({{lo_[0] + long(k % size_[0]), lo_[1] + long(k / size_[0] % size_[1]),
                        lo_[2] + long(k / (size_[0] * size_[1]))}},
                      0);
        break;
      }
  }
  const Eigen::Matrix3d R = Eigen::AngleAxisd(rotate_deg * kPi / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  MaskImage::DirectionType dir = out->GetDirection();
  Eigen::Matrix3d D;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) D(a, b) = dir(a, b);
  D = R * D;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) dir(a, b) = D(a, b);
  const auto o = out->GetOrigin();
  const Eigen::Vector3d origin = moved({o[0], o[1], o[2]}, centroid_, shift, rotate_deg);
  out->SetDirection(dir);
  out->SetOrigin(origin.data());
  return out;
}

MaskImage::Pointer downsample_mask(const MaskImage* mask, int factor) {
  const auto region = mask->GetLargestPossibleRegion();
  MaskImage::SizeType size;
  for (int d = 0; d < 3; ++d) size[d] = std::max<size_t>(1, region.GetSize()[d] / size_t(factor));
  auto out = MaskImage::New();
  out->SetRegions(MaskImage::RegionType(region.GetIndex(), size));
  MaskImage::SpacingType spacing = mask->GetSpacing();
  for (int d = 0; d < 3; ++d) spacing[d] *= factor;
  out->SetSpacing(spacing);
  out->SetDirection(mask->GetDirection());
  MaskImage::PointType origin;  // the coarse voxel's centre is the centre of the fine voxels it covers
  MaskImage::IndexType first = region.GetIndex();
  itk::ContinuousIndex<double, 3> centre;
  for (int d = 0; d < 3; ++d) centre[d] = double(first[d]) + 0.5 * (factor - 1);
  mask->TransformContinuousIndexToPhysicalPoint(centre, origin);
  out->SetOrigin(origin);
  out->Allocate(true);
  const int half = (factor * factor * factor + 1) / 2;
  itk::ImageRegionIteratorWithIndex<MaskImage> it(out, out->GetLargestPossibleRegion());
  for (; !it.IsAtEnd(); ++it) {
    const auto c = it.GetIndex();
    int n = 0;
    for (int z = 0; z < factor; ++z)
      for (int y = 0; y < factor; ++y)
        for (int x = 0; x < factor; ++x)
          n += mask->GetPixel({{first[0] + (c[0] - first[0]) * factor + x, first[1] + (c[1] - first[1]) * factor + y,
                                first[2] + (c[2] - first[2]) * factor + z}}) != 0;
    it.Set(n >= half ? 1 : 0);
  }
  return out;
}

}  // namespace cf
