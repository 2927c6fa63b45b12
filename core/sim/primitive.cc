#include "core/sim/primitive.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "core/common/pose2d.h"

namespace hpose {
namespace {

constexpr double kEps = 1e-12;

// Keeps the nearest candidate with t in (t_min, t_max).
struct HitCollector {
  double t_min;
  double t_max;
  std::optional<RayHit> best;

  void Offer(double t, const Eigen::Vector3d& normal_local) {
    if (!(t > t_min && t < t_max)) return;
    if (best && best->t <= t) return;
    best = RayHit{t, normal_local};
  }
};

// Roots of a t^2 + 2 b t + c = 0; false when there are none.
bool SolveQuadratic(double a, double b, double c, double* t0, double* t1) {
  if (std::abs(a) < kEps) return false;
  const double disc = b * b - a * c;
  if (disc < 0.0) return false;
  const double s = std::sqrt(disc);
  *t0 = (-b - s) / a;
  *t1 = (-b + s) / a;
  return true;
}

void OfferSphere(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& centre,
                 double r, int hemisphere_sign, double h, HitCollector* hits) {
  const Eigen::Vector3d oc = o - centre;
  double t0 = 0.0;
  double t1 = 0.0;
  if (!SolveQuadratic(d.dot(d), oc.dot(d), oc.dot(oc) - r * r, &t0, &t1)) return;
  for (const double t : {t0, t1}) {
    const Eigen::Vector3d p = o + t * d;
    if (hemisphere_sign > 0 && p.z() < h) continue;
    if (hemisphere_sign < 0 && p.z() > -h) continue;
    hits->Offer(t, (p - centre) / r);
  }
}

// The side of a z-aligned cylinder of radius r for |z| <= h.
void OfferTube(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double r, double h,
               HitCollector* hits) {
  double t0 = 0.0;
  double t1 = 0.0;
  const double a = d.x() * d.x() + d.y() * d.y();
  const double b = o.x() * d.x() + o.y() * d.y();
  const double c = o.x() * o.x() + o.y() * o.y() - r * r;
  if (!SolveQuadratic(a, b, c, &t0, &t1)) return;
  for (const double t : {t0, t1}) {
    const Eigen::Vector3d p = o + t * d;
    if (std::abs(p.z()) > h) continue;
    hits->Offer(t, Eigen::Vector3d(p.x() / r, p.y() / r, 0.0));
  }
}

// Points on a sphere of radius r around the origin, roughly `spacing` apart (Fibonacci lattice).
std::vector<Eigen::Vector3d> FibonacciSphere(double r, double spacing) {
  const int n = std::max(8, static_cast<int>(std::ceil(4.0 * kPi * r * r / (spacing * spacing))));
  const double golden_angle = kPi * (3.0 - std::sqrt(5.0));
  std::vector<Eigen::Vector3d> out;
  out.reserve(n);
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n;
    const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden_angle * i;
    out.emplace_back(r * rho * std::cos(phi), r * rho * std::sin(phi), r * z);
  }
  return out;
}

int Steps(double length, double spacing) {
  return std::max(1, static_cast<int>(std::ceil(length / spacing)));
}

// Rings of points on a z-aligned tube of radius r for z in [-h, h].
void SampleTube(double r, double h, double spacing, std::vector<Eigen::Vector3d>* out) {
  const int n_theta = std::max(6, Steps(2.0 * kPi * r, spacing));
  const int n_z = Steps(2.0 * h, spacing);
  for (int k = 0; k <= n_z; ++k) {
    const double z = -h + 2.0 * h * k / n_z;
    for (int j = 0; j < n_theta; ++j) {
      const double a = 2.0 * kPi * j / n_theta;
      out->emplace_back(r * std::cos(a), r * std::sin(a), z);
    }
  }
}

// Concentric rings filling a disc of radius r at height z.
void SampleDisc(double r, double z, double spacing, std::vector<Eigen::Vector3d>* out) {
  const int n_r = Steps(r, spacing);
  for (int j = 0; j <= n_r; ++j) {
    const double rho = r * j / n_r;
    const int n_theta = std::max(1, Steps(2.0 * kPi * rho, spacing));
    for (int k = 0; k < n_theta; ++k) {
      const double a = 2.0 * kPi * k / n_theta;
      out->emplace_back(rho * std::cos(a), rho * std::sin(a), z);
    }
  }
}

}  // namespace

const char* PrimitiveShapeName(PrimitiveShape shape) {
  switch (shape) {
    case PrimitiveShape::kBox:
      return "box";
    case PrimitiveShape::kSphere:
      return "sphere";
    case PrimitiveShape::kCylinder:
      return "cylinder";
    case PrimitiveShape::kCapsule:
      return "capsule";
  }
  return "unknown";
}

std::optional<PrimitiveShape> PrimitiveShapeFromName(const std::string& name) {
  for (const PrimitiveShape s : {PrimitiveShape::kBox, PrimitiveShape::kSphere,
                                 PrimitiveShape::kCylinder, PrimitiveShape::kCapsule}) {
    if (name == PrimitiveShapeName(s)) return s;
  }
  return std::nullopt;
}

Primitive Primitive::Box(std::string name, const Eigen::Vector3d& size_m,
                         const Eigen::Isometry3d& parent_from_local) {
  Primitive p;
  p.shape = PrimitiveShape::kBox;
  p.half_size = 0.5 * size_m;
  p.parent_from_local = parent_from_local;
  p.name = std::move(name);
  return p;
}

Primitive Primitive::Sphere(std::string name, double radius_m, const Eigen::Vector3d& centre) {
  Primitive p;
  p.shape = PrimitiveShape::kSphere;
  p.half_size = Eigen::Vector3d::Constant(radius_m);
  p.parent_from_local = Eigen::Isometry3d::Identity();
  p.parent_from_local.translation() = centre;
  p.name = std::move(name);
  return p;
}

Primitive Primitive::Cylinder(std::string name, double radius_m, double height_m,
                              const Eigen::Isometry3d& parent_from_local) {
  Primitive p;
  p.shape = PrimitiveShape::kCylinder;
  p.half_size = Eigen::Vector3d(radius_m, radius_m, 0.5 * height_m);
  p.parent_from_local = parent_from_local;
  p.name = std::move(name);
  return p;
}

Primitive Primitive::Capsule(std::string name, double radius_m, const Eigen::Vector3d& a,
                             const Eigen::Vector3d& b) {
  Primitive p;
  p.shape = PrimitiveShape::kCapsule;
  const Eigen::Vector3d axis = b - a;
  const double length = axis.norm();
  p.half_size = Eigen::Vector3d(radius_m, radius_m, 0.5 * length);
  p.parent_from_local = Eigen::Isometry3d::Identity();
  if (length > kEps) {
    p.parent_from_local.linear() =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis / length)
            .toRotationMatrix();
  }
  p.parent_from_local.translation() = 0.5 * (a + b);
  p.name = std::move(name);
  return p;
}

Primitive Primitive::Transformed(const Eigen::Isometry3d& new_from_parent) const {
  Primitive p = *this;
  p.parent_from_local = new_from_parent * parent_from_local;
  return p;
}

double Primitive::BoundingRadius() const {
  switch (shape) {
    case PrimitiveShape::kBox:
      return half_size.norm();
    case PrimitiveShape::kSphere:
      return half_size.x();
    case PrimitiveShape::kCylinder:
      return std::hypot(half_size.x(), half_size.z());
    case PrimitiveShape::kCapsule:
      return half_size.x() + half_size.z();
  }
  return half_size.norm();
}

Eigen::AlignedBox3d Primitive::Bounds() const {
  const Eigen::Matrix3d r = parent_from_local.linear();
  const Eigen::Vector3d c = parent_from_local.translation();
  Eigen::Vector3d extent = half_size;
  switch (shape) {
    case PrimitiveShape::kBox:
      extent = r.cwiseAbs() * half_size;
      break;
    case PrimitiveShape::kSphere:
      extent = Eigen::Vector3d::Constant(half_size.x());
      break;
    case PrimitiveShape::kCylinder:
      for (int i = 0; i < 3; ++i) {
        const double a = r(i, 2);
        extent[i] =
            std::abs(a) * half_size.z() + half_size.x() * std::sqrt(std::max(0.0, 1.0 - a * a));
      }
      break;
    case PrimitiveShape::kCapsule:
      extent = r.col(2).cwiseAbs() * half_size.z() + Eigen::Vector3d::Constant(half_size.x());
      break;
  }
  return Eigen::AlignedBox3d(c - extent, c + extent);
}

bool Primitive::Contains(const Eigen::Vector3d& p_parent, double margin_m) const {
  const Eigen::Vector3d p = parent_from_local.inverse() * p_parent;
  const Eigen::Vector3d& h = half_size;
  switch (shape) {
    case PrimitiveShape::kBox:
      return std::abs(p.x()) <= h.x() - margin_m && std::abs(p.y()) <= h.y() - margin_m &&
             std::abs(p.z()) <= h.z() - margin_m;
    case PrimitiveShape::kSphere:
      return p.norm() <= h.x() - margin_m;
    case PrimitiveShape::kCylinder: {
      const double rr = h.x() - margin_m;
      return rr > 0.0 && p.head<2>().squaredNorm() <= rr * rr &&
             std::abs(p.z()) <= h.z() - margin_m;
    }
    case PrimitiveShape::kCapsule: {
      const Eigen::Vector3d nearest(0.0, 0.0, std::clamp(p.z(), -h.z(), h.z()));
      return (p - nearest).norm() <= h.x() - margin_m;
    }
  }
  return false;
}

std::optional<RayHit> Primitive::Intersect(const Eigen::Vector3d& origin,
                                           const Eigen::Vector3d& direction, double t_min,
                                           double t_max) const {
  const Eigen::Matrix3d r = parent_from_local.linear();
  const Eigen::Vector3d o = r.transpose() * (origin - parent_from_local.translation());
  const Eigen::Vector3d d = r.transpose() * direction;
  const Eigen::Vector3d& h = half_size;
  HitCollector hits{t_min, t_max, std::nullopt};
  switch (shape) {
    case PrimitiveShape::kBox: {
      // Each face plane, kept when the hit lies within the face.
      for (int axis = 0; axis < 3; ++axis) {
        if (std::abs(d[axis]) < kEps) continue;
        for (const double side : {-1.0, 1.0}) {
          const double t = (side * h[axis] - o[axis]) / d[axis];
          const Eigen::Vector3d p = o + t * d;
          const int u = (axis + 1) % 3;
          const int v = (axis + 2) % 3;
          if (std::abs(p[u]) > h[u] || std::abs(p[v]) > h[v]) continue;
          Eigen::Vector3d n = Eigen::Vector3d::Zero();
          n[axis] = side;
          hits.Offer(t, n);
        }
      }
      break;
    }
    case PrimitiveShape::kSphere:
      OfferSphere(o, d, Eigen::Vector3d::Zero(), h.x(), 0, 0.0, &hits);
      break;
    case PrimitiveShape::kCylinder:
      OfferTube(o, d, h.x(), h.z(), &hits);
      if (std::abs(d.z()) > kEps) {
        for (const double side : {-1.0, 1.0}) {
          const double t = (side * h.z() - o.z()) / d.z();
          const Eigen::Vector3d p = o + t * d;
          if (p.head<2>().squaredNorm() > h.x() * h.x()) continue;
          hits.Offer(t, Eigen::Vector3d(0.0, 0.0, side));
        }
      }
      break;
    case PrimitiveShape::kCapsule:
      OfferTube(o, d, h.x(), h.z(), &hits);
      OfferSphere(o, d, Eigen::Vector3d(0.0, 0.0, h.z()), h.x(), +1, h.z(), &hits);
      OfferSphere(o, d, Eigen::Vector3d(0.0, 0.0, -h.z()), h.x(), -1, h.z(), &hits);
      break;
  }
  if (!hits.best) return std::nullopt;
  hits.best->normal = (r * hits.best->normal).normalized();
  return hits.best;
}

std::vector<Eigen::Vector3d> Primitive::SampleSurface(double spacing_m) const {
  assert(spacing_m > 0.0);
  std::vector<Eigen::Vector3d> local;
  const Eigen::Vector3d& h = half_size;
  switch (shape) {
    case PrimitiveShape::kBox:
      for (int axis = 0; axis < 3; ++axis) {
        const int u = (axis + 1) % 3;
        const int v = (axis + 2) % 3;
        const int nu = Steps(2.0 * h[u], spacing_m);
        const int nv = Steps(2.0 * h[v], spacing_m);
        for (const double side : {-1.0, 1.0}) {
          for (int i = 0; i <= nu; ++i) {
            for (int j = 0; j <= nv; ++j) {
              Eigen::Vector3d p;
              p[axis] = side * h[axis];
              p[u] = -h[u] + 2.0 * h[u] * i / nu;
              p[v] = -h[v] + 2.0 * h[v] * j / nv;
              local.push_back(p);
            }
          }
        }
      }
      break;
    case PrimitiveShape::kSphere:
      local = FibonacciSphere(h.x(), spacing_m);
      break;
    case PrimitiveShape::kCylinder:
      SampleTube(h.x(), h.z(), spacing_m, &local);
      SampleDisc(h.x(), h.z(), spacing_m, &local);
      SampleDisc(h.x(), -h.z(), spacing_m, &local);
      break;
    case PrimitiveShape::kCapsule:
      SampleTube(h.x(), h.z(), spacing_m, &local);
      for (const Eigen::Vector3d& p : FibonacciSphere(h.x(), spacing_m)) {
        local.push_back(p + Eigen::Vector3d(0.0, 0.0, p.z() >= 0.0 ? h.z() : -h.z()));
      }
      break;
  }
  for (Eigen::Vector3d& p : local) p = parent_from_local * p;
  return local;
}

}  // namespace hpose
