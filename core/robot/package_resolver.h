#ifndef HPOSE_CORE_ROBOT_PACKAGE_RESOLVER_H_
#define HPOSE_CORE_ROBOT_PACKAGE_RESOLVER_H_

#include <string>
#include <vector>

#include "core/common/status.h"

namespace hpose {

// Turns a URDF resource name into a file path, the way ROS tools do:
//  - "package://NAME/REST": NAME is a package directory found in `package_paths` (searched in
//    order; each entry is a package itself, when its package.xml names NAME or its directory is
//    called NAME, or a tree searched for one up to 4 levels deep), then among the URDF file's
//    ancestor directories (a package.xml naming NAME);
//  - "file://ABSOLUTE" and absolute paths as they are;
//  - other relative paths relative to `urdf_dir`.
// Does not check that the file exists. Fails (kNotFound) when the package cannot be found,
// naming it and the directories searched; kInvalidArgument on an empty or malformed name.
Result<std::string> ResolveUrdfResource(const std::string& uri, const std::string& urdf_dir,
                                        const std::vector<std::string>& package_paths);

}  // namespace hpose

#endif  // HPOSE_CORE_ROBOT_PACKAGE_RESOLVER_H_
