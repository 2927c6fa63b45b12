#include "core/depth/veil_filter.h"

#include <algorithm>
#include <cassert>
#include <cstddef>

#include "core/depth/point_lanes.h"

namespace hpose {

bool IsVeilPoint(const PointCloud& cloud, int u, int v, float cos2_veil) {
  const int width = cloud.width, height = cloud.height;
  const Eigen::Vector3f& p = cloud.points[static_cast<size_t>(v) * width + u];
  const float p2 = p.squaredNorm();
  const int du[4] = {kVeilPixelStep, -kVeilPixelStep, 0, 0};
  const int dv[4] = {0, 0, kVeilPixelStep, -kVeilPixelStep};
  for (int k = 0; k < 4; ++k) {
    const int nu = u + du[k];
    const int nv = v + dv[k];
    if (nu < 0 || nu >= width || nv < 0 || nv >= height) continue;
    const Eigen::Vector3f& q = cloud.points[static_cast<size_t>(nv) * width + nu];
    if (!q.allFinite()) continue;
    const Eigen::Vector3f step = q - p;
    const float along = step.dot(p);
    if (along * along > cos2_veil * step.squaredNorm() * p2) return true;
  }
  return false;
}

namespace {

// The veil test of pixel `pixel`, the scalar way.
bool VeilAt(const PointCloud& cloud, int pixel, float cos2_veil) {
  return IsVeilPoint(cloud, pixel % cloud.width, pixel / cloud.width, cos2_veil);
}

size_t KeepScalar(const PointCloud& cloud, float cos2_veil, Eigen::Vector3f* kept, int* index,
                  size_t count) {
  size_t out = 0;
  for (size_t k = 0; k < count; ++k) {
    if (VeilAt(cloud, index[k], cos2_veil)) continue;
    kept[out] = kept[k];
    index[out] = index[k];
    ++out;
  }
  return out;
}

// The kept entries (in order) when each pixel's veil bit comes from the group of kGroup pixels
// it lies in, `lanes.Mask` making the group's bits once per group met; a group the lanes cannot
// take (across a row's end, or at the image's) leaves its pixels to the scalar test.
template <size_t kGroup, class Lanes>
size_t KeepByGroups(const Lanes& lanes, const PointCloud& cloud, float cos2_veil,
                    Eigen::Vector3f* kept, int* index, size_t count) {
  size_t out = 0;
  size_t group = ~size_t{0};
  bool in_lanes = false;
  unsigned bits = 0;
  for (size_t k = 0; k < count; ++k) {
    const size_t pixel = static_cast<size_t>(index[k]);
    if ((pixel & ~(kGroup - 1)) != group) {
      group = pixel & ~(kGroup - 1);
      in_lanes = lanes.Mask(group, &bits);
    }
    const bool drop = in_lanes ? ((bits >> (pixel & (kGroup - 1))) & 1u) != 0
                               : VeilAt(cloud, static_cast<int>(pixel), cos2_veil);
    if (drop) continue;
    kept[out] = kept[k];
    index[out] = index[k];
    ++out;
  }
  return out;
}

#ifdef HPOSE_POINT_LANES
using rounded::Add;
using rounded::Mul;
using rounded::Sub;

// x0 + (x1 + x2): how Eigen sums a 3-vector's terms (dot, squaredNorm).
[[gnu::target("avx512f")]] inline __m512 Sum3(__m512 x0, __m512 x1, __m512 x2) {
  return Add(x0, Add(x1, x2));
}

// The veil test of sixteen pixels of one row at once, IsVeilPoint's arithmetic lane by lane.
class VeilLanes {
 public:
  [[gnu::target("avx512f")]] VeilLanes(const PointCloud& cloud, float cos2_veil)
      : cloud_(cloud), cos2_(_mm512_set1_ps(cos2_veil)) {}

  // The veil bits of pixels first .. first + 15 (bit i: pixel first + i), or false when they do
  // not lie in one row with room for the loads around them (then the scalar test decides).
  [[gnu::target("avx512f,avx512dq")]] bool Mask(size_t first, unsigned* bits) const {
    const size_t width = static_cast<size_t>(cloud_.width);
    const size_t height = static_cast<size_t>(cloud_.height);
    const size_t n = cloud_.points.size();
    const size_t s = kVeilPixelStep;
    const size_t v = first / width, u0 = first % width;
    if (u0 + 16 > width || first < s || first + 16 + s > n) return false;
    const PointLanes p = lanes_.Load(cloud_.points[first].data());
    const __m512 p2 = Sum3(Mul(p.x, p.x), Mul(p.y, p.y), Mul(p.z, p.z));
    // Lane i is pixel u0 + i: its neighbour to the right exists while u0 + i + s < width, to
    // the left from i >= s - u0.
    const size_t right = std::min<size_t>(16, width - u0 - std::min(width - u0, s));
    const size_t left_from = u0 >= s ? 0 : s - u0;
    __mmask16 veil = 0;
    veil |= Test(p, p2, first + s) & static_cast<__mmask16>((1u << right) - 1);
    veil |= Test(p, p2, first - s) & static_cast<__mmask16>(0xFFFFu << left_from);
    if (v + s < height) veil |= Test(p, p2, first + s * width);
    if (v >= s) veil |= Test(p, p2, first - s * width);
    *bits = veil;
    return true;
  }

 private:
  // The lanes whose neighbour q (the sixteen points from `from`) is finite and lies within the
  // veil angle of the lane's ray.
  [[gnu::target("avx512f,avx512dq")]] __mmask16 Test(const PointLanes& p, __m512 p2,
                                                     size_t from) const {
    const PointLanes q = lanes_.Load(cloud_.points[from].data());
    // Not NaN nor infinite (fpclass 0x99: quiet and signalling NaN, +inf, -inf).
    const __mmask16 finite = static_cast<__mmask16>(~(_mm512_fpclass_ps_mask(q.x, 0x99) |
                                                      _mm512_fpclass_ps_mask(q.y, 0x99) |
                                                      _mm512_fpclass_ps_mask(q.z, 0x99)));
    const __m512 sx = Sub(q.x, p.x), sy = Sub(q.y, p.y), sz = Sub(q.z, p.z);
    const __m512 along = Sum3(Mul(sx, p.x), Mul(sy, p.y), Mul(sz, p.z));
    const __m512 step2 = Sum3(Mul(sx, sx), Mul(sy, sy), Mul(sz, sz));
    return finite & _mm512_cmp_ps_mask(Mul(along, along), Mul(Mul(cos2_, step2), p2), _CMP_GT_OQ);
  }

  const PointCloud& cloud_;
  const __m512 cos2_;
  const PointDeinterleaver lanes_;
};

// Each entry's pixel looked up in the bits of its group of sixteen (made once per group met).
[[gnu::target("avx512f,avx512dq")]] size_t KeepAvx512(const PointCloud& cloud, float cos2_veil,
                                                      Eigen::Vector3f* kept, int* index,
                                                      size_t count) {
  const VeilLanes veil(cloud, cos2_veil);
  return KeepByGroups<16>(veil, cloud, cos2_veil, kept, index, count);
}
// x0 + (x1 + x2), eight lanes (the AVX2 target has no fused multiply-add).
[[gnu::target("avx2")]] inline __m256 Sum3(__m256 x0, __m256 x1, __m256 x2) {
  return _mm256_add_ps(x0, _mm256_add_ps(x1, x2));
}

// VeilLanes with AVX2: eight pixels of one row at once.
class VeilLanes8 {
 public:
  [[gnu::target("avx2")]] VeilLanes8(const PointCloud& cloud, float cos2_veil)
      : cloud_(cloud), cos2_(_mm256_set1_ps(cos2_veil)) {}

  // The veil bits of pixels first .. first + 7, or false when they do not lie in one row with
  // room for the loads around them.
  [[gnu::target("avx2")]] bool Mask(size_t first, unsigned* bits) const {
    const size_t width = static_cast<size_t>(cloud_.width);
    const size_t height = static_cast<size_t>(cloud_.height);
    const size_t n = cloud_.points.size();
    const size_t s = kVeilPixelStep;
    const size_t v = first / width, u0 = first % width;
    if (u0 + 8 > width || first < s || first + 8 + s > n) return false;
    const PointLanes8 p = shuffles_.Load(cloud_.points[first].data());
    const __m256 p2 =
        Sum3(_mm256_mul_ps(p.x, p.x), _mm256_mul_ps(p.y, p.y), _mm256_mul_ps(p.z, p.z));
    const size_t right = std::min<size_t>(8, width - u0 - std::min(width - u0, s));
    const size_t left_from = u0 >= s ? 0 : s - u0;
    unsigned veil = 0;
    veil |= Test(p, p2, first + s) & ((1u << right) - 1);
    veil |= Test(p, p2, first - s) & (0xFFu << left_from);
    if (v + s < height) veil |= Test(p, p2, first + s * width);
    if (v >= s) veil |= Test(p, p2, first - s * width);
    *bits = veil & 0xFFu;
    return true;
  }

 private:
  [[gnu::target("avx2")]] unsigned Test(const PointLanes8& p, __m256 p2, size_t from) const {
    const PointLanes8 q = shuffles_.Load(cloud_.points[from].data());
    // v - v is 0 exactly when v is finite.
    const __m256 zero = _mm256_setzero_ps();
    const __m256 finite =
        _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(_mm256_sub_ps(q.x, q.x), zero, _CMP_EQ_OQ),
                                    _mm256_cmp_ps(_mm256_sub_ps(q.y, q.y), zero, _CMP_EQ_OQ)),
                      _mm256_cmp_ps(_mm256_sub_ps(q.z, q.z), zero, _CMP_EQ_OQ));
    const __m256 sx = _mm256_sub_ps(q.x, p.x), sy = _mm256_sub_ps(q.y, p.y),
                 sz = _mm256_sub_ps(q.z, p.z);
    const __m256 along =
        Sum3(_mm256_mul_ps(sx, p.x), _mm256_mul_ps(sy, p.y), _mm256_mul_ps(sz, p.z));
    const __m256 step2 = Sum3(_mm256_mul_ps(sx, sx), _mm256_mul_ps(sy, sy), _mm256_mul_ps(sz, sz));
    const __m256 within = _mm256_cmp_ps(_mm256_mul_ps(along, along),
                                        _mm256_mul_ps(_mm256_mul_ps(cos2_, step2), p2), _CMP_GT_OQ);
    return static_cast<unsigned>(_mm256_movemask_ps(_mm256_and_ps(finite, within)));
  }

  const PointCloud& cloud_;
  const __m256 cos2_;
  const PointShuffles8 shuffles_;
};

// The same with groups of eight.
[[gnu::target("avx2")]] size_t KeepAvx2(const PointCloud& cloud, float cos2_veil,
                                        Eigen::Vector3f* kept, int* index, size_t count) {
  const VeilLanes8 veil(cloud, cos2_veil);
  return KeepByGroups<8>(veil, cloud, cos2_veil, kept, index, count);
}
#else
constexpr auto* KeepAvx512 = &KeepScalar;
constexpr auto* KeepAvx2 = &KeepScalar;
#endif

void Drop(const PointCloud& cloud, float cos2_veil, std::vector<Eigen::Vector3f>* kept,
          std::vector<int>* index, LanePath path) {
  if (!cloud.organised()) return;  // no neighbours to test against.
  const size_t count = std::min(kept->size(), index->size());
  const auto keep = path == LanePath::kFastest && PointLanesAvailable()   ? KeepAvx512
                    : path != LanePath::kScalar && PointLanes8Available() ? KeepAvx2
                                                                          : KeepScalar;
  const size_t out = keep(cloud, cos2_veil, kept->data(), index->data(), count);
  kept->resize(out);
  index->resize(out);
}

}  // namespace

void DropVeilPoints(const PointCloud& cloud, float cos2_veil, std::vector<Eigen::Vector3f>* kept,
                    std::vector<int>* index) {
  Drop(cloud, cos2_veil, kept, index, LanePath::kFastest);
}

void DropVeilPointsAvx2(const PointCloud& cloud, float cos2_veil,
                        std::vector<Eigen::Vector3f>* kept, std::vector<int>* index) {
  assert(VeilFilterAvx2Available());
  Drop(cloud, cos2_veil, kept, index, LanePath::kAvx2);
}

void DropVeilPointsScalar(const PointCloud& cloud, float cos2_veil,
                          std::vector<Eigen::Vector3f>* kept, std::vector<int>* index) {
  Drop(cloud, cos2_veil, kept, index, LanePath::kScalar);
}

bool VeilFilterVectorised() { return PointLanesAvailable() || PointLanes8Available(); }

bool VeilFilterAvx2Available() { return PointLanes8Available(); }

}  // namespace hpose
