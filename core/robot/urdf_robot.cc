#include "core/robot/urdf_robot.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>
#include <utility>
#include <vector>

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include "core/robot/mesh_file.h"
#include "core/robot/package_resolver.h"

namespace hpose {
namespace {

namespace fs = std::filesystem;

// Collects urdfdom's console messages so a parse failure can say why.
class CapturingOutput final : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN)
      messages_ += (messages_.empty() ? "" : "; ") + text;
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) has_error_ = true;
  }
  const std::string& messages() const { return messages_; }
  // An error was logged: urdfdom logs one and leaves out what it could not read (a visual or
  // collision element whose numbers it cannot parse) yet still returns a model.
  bool has_error() const { return has_error_; }

 private:
  std::string messages_;
  bool has_error_ = false;
};

Eigen::Isometry3d ToIsometry(const urdf::Pose& p) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z)
                   .normalized()
                   .toRotationMatrix();
  t.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  return t;
}

// Lengths of a URDF primitive (box sizes, radii, a cylinder's length): an error naming `what`
// unless all are finite and not negative. urdfdom passes negative ones on; such a shape would
// turn inside out in the template.
bool CheckLengths(const std::string& link, const std::string& what,
                  std::initializer_list<double> values, Error* error) {
  for (const double v : values) {
    if (std::isfinite(v) && v >= 0.0) continue;
    std::ostringstream msg;
    msg << "link '" << link << "': " << what << " (";
    const char* sep = "";
    for (const double x : values) {
      msg << sep << x;
      sep = " ";
    }
    msg << ") must be finite and not negative";
    *error = MakeError(ErrorCode::kInvalidArgument, msg.str());
    return false;
  }
  return true;
}

// A primitive's largest extent `across_m`: an error naming the link when it is wider than a
// template may span along an axis, before tessellating it (a 100 km sphere took all memory).
bool CheckSpan(const std::string& link, const std::string& what, double across_m, Error* error) {
  if (across_m <= kMaxTemplateBodyM) return true;
  std::ostringstream msg;
  msg << "link '" << link << "': " << what << " makes a shape " << across_m
      << " m across, more than the " << kMaxTemplateBodyM
      << " m a template may span (are its lengths in millimetres?)";
  *error = MakeError(ErrorCode::kInvalidArgument, msg.str());
  return false;
}

const char* JointTypeName(int type) {
  switch (type) {
    case urdf::Joint::REVOLUTE:
      return "revolute";
    case urdf::Joint::CONTINUOUS:
      return "continuous";
    case urdf::Joint::PRISMATIC:
      return "prismatic";
    case urdf::Joint::FLOATING:
      return "floating";
    case urdf::Joint::PLANAR:
      return "planar";
    case urdf::Joint::FIXED:
      return "fixed";
    default:
      return "unknown";
  }
}

// One URDF geometry as triangles in its own frame (before the visual/collision origin).
struct GeometryLoader {
  const UrdfLoadOptions& options;
  std::string urdf_dir;
  std::map<std::string, Result<TriangleMesh>> read;  // mesh files by resolved path.
  std::vector<SkippedMesh>* skipped;

  // Reads the mesh files of these geometries that exist, all in one child process (see
  // ReadMeshFiles): what Load then finds read. Names that cannot be resolved are left to Load.
  void ReadMeshesOf(const std::vector<const urdf::Geometry*>& geometries) {
    std::vector<std::string> paths;
    for (const urdf::Geometry* g : geometries) {
      if (g == nullptr || g->type != urdf::Geometry::MESH) continue;
      Result<std::string> path = ResolveUrdfResource(static_cast<const urdf::Mesh*>(g)->filename,
                                                     urdf_dir, options.package_paths);
      std::error_code ec;
      if (!path.ok() || !fs::is_regular_file(*path, ec) || read.count(*path) > 0 ||
          std::find(paths.begin(), paths.end(), *path) != paths.end()) {
        continue;
      }
      paths.push_back(*path);
    }
    std::vector<Result<TriangleMesh>> meshes = ReadMeshFiles(paths);
    for (size_t i = 0; i < paths.size(); ++i) read.emplace(paths[i], std::move(meshes[i]));
  }

  // Returns false (and sets *error) when the robot cannot be loaded.
  bool Load(const std::string& link, const urdf::Geometry& geometry, TriangleMesh* out,
            Error* error) {
    const double edge = options.primitive_max_edge_m;
    switch (geometry.type) {
      case urdf::Geometry::BOX: {
        const auto& box = static_cast<const urdf::Box&>(geometry);
        if (!CheckLengths(link, "box size", {box.dim.x, box.dim.y, box.dim.z}, error) ||
            !CheckSpan(link, "box size", std::max({box.dim.x, box.dim.y, box.dim.z}), error)) {
          return false;
        }
        *out = TessellatePrimitive(
            Primitive::Box(link, Eigen::Vector3d(box.dim.x, box.dim.y, box.dim.z),
                           Eigen::Isometry3d::Identity()),
            edge);
        return true;
      }
      case urdf::Geometry::CYLINDER: {
        const auto& c = static_cast<const urdf::Cylinder&>(geometry);
        if (!CheckLengths(link, "cylinder radius and length", {c.radius, c.length}, error) ||
            !CheckSpan(link, "cylinder radius and length", std::max(2.0 * c.radius, c.length),
                       error)) {
          return false;
        }
        *out = TessellatePrimitive(
            Primitive::Cylinder(link, c.radius, c.length, Eigen::Isometry3d::Identity()), edge);
        return true;
      }
      case urdf::Geometry::SPHERE: {
        const auto& s = static_cast<const urdf::Sphere&>(geometry);
        if (!CheckLengths(link, "sphere radius", {s.radius}, error) ||
            !CheckSpan(link, "sphere radius", 2.0 * s.radius, error)) {
          return false;
        }
        *out =
            TessellatePrimitive(Primitive::Sphere(link, s.radius, Eigen::Vector3d::Zero()), edge);
        return true;
      }
      case urdf::Geometry::MESH:
        return LoadMesh(link, static_cast<const urdf::Mesh&>(geometry), out, error);
    }
    *error = MakeError(ErrorCode::kInvalidArgument, "link '" + link + "': unknown geometry type");
    return false;
  }

  bool LoadMesh(const std::string& link, const urdf::Mesh& mesh, TriangleMesh* out, Error* error) {
    if (!std::isfinite(mesh.scale.x) || !std::isfinite(mesh.scale.y) ||
        !std::isfinite(mesh.scale.z)) {
      std::ostringstream msg;
      msg << "link '" << link << "': mesh " << mesh.filename << ": scale (" << mesh.scale.x << " "
          << mesh.scale.y << " " << mesh.scale.z << ") must be finite";
      *error = MakeError(ErrorCode::kInvalidArgument, msg.str());
      return false;
    }
    Result<std::string> path = ResolveUrdfResource(mesh.filename, urdf_dir, options.package_paths);
    std::string reason;
    if (!path.ok()) {
      reason = path.error().message;
    } else if (std::error_code ec; !fs::is_regular_file(*path, ec)) {
      reason = "file does not exist";
    } else {
      auto it = read.find(*path);
      if (it == read.end()) it = read.emplace(*path, ReadMeshFile(*path)).first;
      if (it->second.ok()) {
        *out = *it->second;
      } else {
        reason = "cannot read it: " + it->second.error().message;
      }
    }
    if (!reason.empty()) {
      const std::string where = path.ok() ? *path : "";
      if (options.allow_missing) {
        skipped->push_back({link, mesh.filename, where, reason});
        out->vertices.clear();
        out->triangles.clear();
        return true;
      }
      *error = MakeError(path.ok() && reason == "file does not exist" ? ErrorCode::kNotFound
                                                                      : ErrorCode::kDataLoss,
                         "link '" + link + "': mesh " + (where.empty() ? mesh.filename : where) +
                             ": " + reason + " (use --allow-missing to skip it)");
      return false;
    }
    const Eigen::Vector3f scale(static_cast<float>(mesh.scale.x), static_cast<float>(mesh.scale.y),
                                static_cast<float>(mesh.scale.z));
    for (Eigen::Vector3f& v : out->vertices) v = v.cwiseProduct(scale);
    return true;
  }
};

// The shapes of `link` that `kind` selects (its visual or its collision elements): each one's
// geometry, and its origin in the link.
std::vector<std::pair<const urdf::Geometry*, urdf::Pose>> SelectedShapes(const urdf::Link& link,
                                                                         UrdfGeometryKind kind) {
  std::vector<std::pair<const urdf::Geometry*, urdf::Pose>> shapes;
  if (kind == UrdfGeometryKind::kVisual) {
    for (const urdf::VisualSharedPtr& v : link.visual_array) {
      if (v != nullptr) shapes.emplace_back(v->geometry.get(), v->origin);
    }
  } else {
    for (const urdf::CollisionSharedPtr& c : link.collision_array) {
      if (c != nullptr) shapes.emplace_back(c->geometry.get(), c->origin);
    }
  }
  return shapes;
}

// A description still written in xacro (ROS's XML macros: <xacro:...> elements, ${...}
// expressions) is what urdfdom rejects most often; say so, and how to expand it.
std::string XacroHint(const std::string& text, const std::string& path) {
  if (text.find("<xacro:") == std::string::npos && text.find("xmlns:xacro") == std::string::npos) {
    return "";
  }
  const std::string stem = fs::path(path).filename().string();
  std::string plain = stem;
  if (const size_t dot = plain.rfind(".xacro"); dot != std::string::npos) plain.erase(dot);
  if (plain == stem || plain.empty()) plain = "robot.urdf";
  return " (the file uses xacro macros: expand it to a plain URDF first, e.g. `xacro " + stem +
         " > " + plain + "`, then pass that)";
}

}  // namespace

bool UrdfJointInfo::Settable() const {
  return mimic_of.empty() && (type == "revolute" || type == "continuous" || type == "prismatic");
}

Result<UrdfRobot> UrdfRobot::Load(const std::string& urdf_path, const UrdfLoadOptions& options) {
  std::ifstream in(urdf_path);
  if (!in) return MakeError(ErrorCode::kNotFound, "cannot read URDF file " + urdf_path);
  std::ostringstream text;
  text << in.rdbuf();

  urdf::ModelInterfaceSharedPtr model;
  {
    // urdfdom reports through console_bridge's global handler: capture it for the message.
    static std::mutex mutex;
    std::lock_guard<std::mutex> lock(mutex);
    CapturingOutput output;
    console_bridge::OutputHandler* previous = console_bridge::getOutputHandler();
    console_bridge::useOutputHandler(&output);
    model = urdf::parseURDF(text.str());
    console_bridge::useOutputHandler(previous);
    if (model == nullptr) {
      return MakeError(ErrorCode::kInvalidArgument,
                       urdf_path + " is not a valid URDF" +
                           (output.messages().empty() ? "" : ": " + output.messages()) +
                           XacroHint(text.str(), urdf_path));
    }
    if (output.has_error()) {
      return MakeError(ErrorCode::kInvalidArgument,
                       urdf_path + ": the URDF parser left parts of it out: " + output.messages() +
                           XacroHint(text.str(), urdf_path));
    }
  }
  if (!(options.primitive_max_edge_m > 0.0)) {
    return MakeError(ErrorCode::kInvalidArgument, "primitive_max_edge_m must be positive");
  }

  UrdfRobot robot;
  robot.name_ = model->getName();
  robot.root_link_ = model->getRoot()->name;
  GeometryLoader loader{options, fs::path(urdf_path).parent_path().string(), {}, &robot.skipped_};
  {
    std::vector<const urdf::Geometry*> geometries;
    for (const auto& [name, link] : model->links_) {
      if (link == nullptr) continue;
      for (const auto& shape : SelectedShapes(*link, options.geometry)) {
        geometries.push_back(shape.first);
      }
    }
    loader.ReadMeshesOf(geometries);
  }
  // Breadth first from the root, so parents come before children.
  std::vector<urdf::LinkConstSharedPtr> queue{model->getRoot()};
  for (size_t i = 0; i < queue.size(); ++i) {
    const urdf::LinkConstSharedPtr& link = queue[i];
    Link l;
    l.name = link->name;
    if (link->parent_joint != nullptr) {
      const urdf::Joint& j = *link->parent_joint;
      Joint joint;
      joint.info.name = j.name;
      joint.info.type = JointTypeName(j.type);
      joint.info.parent_link = j.parent_link_name;
      joint.info.child_link = j.child_link_name;
      if (j.limits != nullptr &&
          (j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::PRISMATIC)) {
        joint.info.has_limits = true;
        joint.info.lower = j.limits->lower;
        joint.info.upper = j.limits->upper;
      }
      if (j.mimic != nullptr) {
        joint.info.mimic_of = j.mimic->joint_name;
        joint.info.mimic_multiplier = j.mimic->multiplier;
        joint.info.mimic_offset = j.mimic->offset;
      }
      joint.parent_from_origin = ToIsometry(j.parent_to_joint_origin_transform);
      const Eigen::Vector3d axis(j.axis.x, j.axis.y, j.axis.z);
      if (!joint.parent_from_origin.matrix().allFinite() || !axis.allFinite()) {
        return MakeError(ErrorCode::kInvalidArgument,
                         "joint '" + j.name + "': its origin or axis is not finite");
      }
      joint.axis = axis.norm() > 0.0 ? axis.normalized() : Eigen::Vector3d::UnitX();
      for (size_t p = 0; p < robot.links_.size(); ++p) {
        if (robot.links_[p].name == j.parent_link_name) joint.parent_link = static_cast<int>(p);
      }
      joint.child_link = static_cast<int>(robot.links_.size());
      l.parent_joint = static_cast<int>(robot.joints_.size());
      robot.joints_.push_back(joint);
      robot.joint_infos_.push_back(joint.info);
    }
    auto add_shape = [&](const urdf::Geometry* geometry, const urdf::Pose& origin) -> Status {
      if (geometry == nullptr) return Status::Ok();
      TriangleMesh shape;
      Error error;
      if (!loader.Load(link->name, *geometry, &shape, &error)) return error;
      const Eigen::Isometry3d link_from_shape = ToIsometry(origin);
      if (!link_from_shape.matrix().allFinite()) {
        return MakeError(ErrorCode::kInvalidArgument,
                         "link '" + link->name + "': a shape's origin is not finite");
      }
      l.shapes.Append(shape, link_from_shape);
      return Status::Ok();
    };
    for (const auto& [geometry, origin] : SelectedShapes(*link, options.geometry)) {
      if (Status s = add_shape(geometry, origin); !s.ok()) return s.error();
    }
    robot.links_.push_back(std::move(l));
    for (const urdf::LinkSharedPtr& child : link->child_links) queue.push_back(child);
  }
  return robot;
}

std::vector<std::string> UrdfRobot::LinkNames() const {
  std::vector<std::string> names;
  for (const Link& l : links_) names.push_back(l.name);
  return names;
}

size_t UrdfRobot::TriangleCount() const {
  size_t n = 0;
  for (const Link& l : links_) n += l.shapes.triangles.size();
  return n;
}

Result<PosedRobot> UrdfRobot::Pose(const JointValues& positions,
                                   const std::string& reference_link) const {
  // Check the names and values given.
  std::map<std::string, const Joint*> by_name;
  for (const Joint& j : joints_) by_name[j.info.name] = &j;
  std::string unknown;
  for (const auto& [name, value] : positions) {
    if (by_name.count(name) == 0) unknown += (unknown.empty() ? "'" : ", '") + name + "'";
  }
  if (!unknown.empty()) {
    return MakeError(ErrorCode::kInvalidArgument, "robot '" + name_ + "' has no joint " + unknown);
  }
  PosedRobot posed;
  std::map<std::string, double> q;
  for (const auto& [name, value] : positions) {
    const UrdfJointInfo& info = by_name[name]->info;
    if (!info.Settable()) {
      return MakeError(ErrorCode::kInvalidArgument,
                       "joint '" + name + "' cannot be set: it is " +
                           (info.mimic_of.empty() ? "a " + info.type + " joint"
                                                  : "a mimic of '" + info.mimic_of + "'"));
    }
    if (info.has_limits && (value < info.lower - 1e-9 || value > info.upper + 1e-9)) {
      std::ostringstream msg;
      msg << "joint '" << name << "' position " << value << " is outside its limits [" << info.lower
          << ", " << info.upper << "]";
      return MakeError(ErrorCode::kInvalidArgument, msg.str());
    }
    q[name] = value;
  }
  for (const Joint& j : joints_) {
    const UrdfJointInfo& info = j.info;
    if (info.mimic_of.empty()) continue;
    auto leader = q.find(info.mimic_of);
    const double v =
        info.mimic_multiplier * (leader == q.end() ? 0.0 : leader->second) + info.mimic_offset;
    q[info.name] = v;
    if (info.has_limits && (v < info.lower - 1e-9 || v > info.upper + 1e-9)) {
      std::ostringstream msg;
      msg << "mimic joint '" << info.name << "' follows '" << info.mimic_of << "' to " << v
          << ", outside its limits [" << info.lower << ", " << info.upper << "]";
      posed.notes.push_back(msg.str());
    }
  }

  // Forward kinematics in the root frame.
  std::vector<Eigen::Isometry3d> root_from_link(links_.size(), Eigen::Isometry3d::Identity());
  for (size_t i = 0; i < links_.size(); ++i) {
    if (links_[i].parent_joint < 0) continue;
    const Joint& j = joints_[links_[i].parent_joint];
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
    const auto it = q.find(j.info.name);
    const double v = it == q.end() ? 0.0 : it->second;
    if (j.info.type == "revolute" || j.info.type == "continuous") {
      motion.linear() = Eigen::AngleAxisd(v, j.axis).toRotationMatrix();
    } else if (j.info.type == "prismatic") {
      motion.translation() = v * j.axis;
    }
    root_from_link[i] = root_from_link[j.parent_link] * j.parent_from_origin * motion;
  }
  // The limb of every link: the moving joint of the trunk it hangs from (-1: the trunk itself,
  // the root link and the links fixed to it). Parents come before children.
  std::vector<int> limb(links_.size(), -1);
  for (size_t i = 0; i < links_.size(); ++i) {
    if (links_[i].parent_joint < 0) continue;
    const Joint& j = joints_[links_[i].parent_joint];
    limb[i] = limb[j.parent_link] >= 0 ? limb[j.parent_link]
              : j.info.type == "fixed" ? -1
                                       : links_[i].parent_joint;
  }
  std::vector<float> limb_lowest(joints_.size(), std::numeric_limits<float>::infinity());
  TriangleMesh root_mesh;
  int reference = reference_link.empty() ? 0 : -1;
  for (size_t i = 0; i < links_.size(); ++i) {
    const size_t first = root_mesh.vertices.size();
    root_mesh.Append(links_[i].shapes, root_from_link[i]);
    for (size_t k = first; limb[i] >= 0 && k < root_mesh.vertices.size(); ++k) {
      limb_lowest[limb[i]] = std::min(limb_lowest[limb[i]], root_mesh.vertices[k].z());
    }
    // Single-precision vertices this far out keep no shape at a voxel's scale (see
    // kMaxTemplateOffsetM): name the link rather than make a template of what is left.
    float farthest = 0.0f;
    for (size_t k = first; k < root_mesh.vertices.size(); ++k) {
      farthest = std::max(farthest, root_mesh.vertices[k].cwiseAbs().maxCoeff());
    }
    if (farthest > kMaxTemplateOffsetM) {
      std::ostringstream msg;
      msg.precision(3);
      msg << "link '" << links_[i].name << "': its shapes lie " << farthest << " m from the "
          << "root link, more than the " << kMaxTemplateOffsetM << " m a template may; is a "
          << "joint or visual origin in other units?";
      return MakeError(ErrorCode::kInvalidArgument, msg.str());
    }
    if (links_[i].name == reference_link) reference = static_cast<int>(i);
  }
  if (reference < 0) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "robot '" + name_ + "' has no link '" + reference_link + "'");
  }
  if (root_mesh.empty()) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "robot '" + name_ + "' has no shape to make a template of");
  }

  // The template frame: reference link origin on the floor, its x axis on the floor.
  const Eigen::Isometry3d& root_from_ref = root_from_link[reference];
  const Eigen::Vector3d x_axis = root_from_ref.linear().col(0);
  if (std::hypot(x_axis.x(), x_axis.y()) < 0.1) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "reference link '" + links_[reference].name +
                         "' has its x axis (nearly) vertical: choose another reference link");
  }
  Eigen::Isometry3d root_from_template = Eigen::Isometry3d::Identity();
  root_from_template.linear() =
      Eigen::AngleAxisd(std::atan2(x_axis.y(), x_axis.x()), Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  root_from_template.translation() =
      Eigen::Vector3d(root_from_ref.translation().x(), root_from_ref.translation().y(),
                      root_mesh.Bounds().min().z());
  posed.template_from_root = root_from_template.inverse();
  posed.reference_link = links_[reference].name;
  for (size_t i = 0; i < links_.size(); ++i) {
    posed.template_from_link[links_[i].name] = posed.template_from_root * root_from_link[i];
  }
  // The free limbs: those whose lowest point stays clear of the floor.
  const Eigen::AlignedBox3d bounds = root_mesh.Bounds();
  const double clearance = bounds.min().z() + kFreeLimbClearance * bounds.sizes().z();
  for (size_t i = 0; i < links_.size(); ++i) {
    if (limb[i] < 0 || !(limb_lowest[limb[i]] > clearance)) continue;
    posed.free_limbs.Append(links_[i].shapes, posed.template_from_root * root_from_link[i]);
  }
  for (size_t j = 0; j < joints_.size(); ++j) {
    if (std::isfinite(limb_lowest[j]) && limb_lowest[j] > clearance) {
      posed.free_limb_joints.push_back(joints_[j].info.name);
    }
  }
  root_mesh.Transform(posed.template_from_root);
  // The lowest vertex is on the floor by construction; float rounding may leave it a hair below.
  for (Eigen::Vector3f& v : root_mesh.vertices) v.z() = std::max(v.z(), 0.0f);
  posed.mesh = std::move(root_mesh);
  return posed;
}

}  // namespace hpose
