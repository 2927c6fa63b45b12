#ifndef HPOSE_CORE_ROBOT_MESH_FILE_H_
#define HPOSE_CORE_ROBOT_MESH_FILE_H_

#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/sim/triangle_mesh.h"

namespace hpose {

// Every triangle of a mesh file in any format assimp reads (STL, COLLADA, OBJ...), its nodes'
// transforms applied, in the file's own units. The file is read in a child process (this
// program again, see RunSelfAsChild): assimp trusts what it parses, and some damaged files make
// it crash (a COLLADA float_array without its count) or never finish, which here are errors
// naming the file instead of the caller's crash or hang. Errors are kDataLoss, saying what is
// wrong. Where no child can be started the file is read in this process.
// A child that is `timeout_s` on one file is killed.
Result<TriangleMesh> ReadMeshFile(const std::string& path, double timeout_s = 120.0);

// ReadMeshFile for several files, one result each in their order, read in one child (a file
// that ends the child is that file's error, and the files after it are read in another).
std::vector<Result<TriangleMesh>> ReadMeshFiles(const std::vector<std::string>& paths,
                                                double timeout_s = 120.0);

// The same, read in this process (the child's own reading; for files known to be sound).
Result<TriangleMesh> ReadMeshFileInProcess(const std::string& path);

}  // namespace hpose

#endif  // HPOSE_CORE_ROBOT_MESH_FILE_H_
