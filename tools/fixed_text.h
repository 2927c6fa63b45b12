#ifndef HPOSE_TOOLS_FIXED_TEXT_H_
#define HPOSE_TOOLS_FIXED_TEXT_H_

#include <string>

namespace hpose::tools {

// `v` in fixed notation with `decimals` digits after the point ("%.*f"), as the commands print
// figures in their reports.
std::string Fixed(double v, int decimals);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_FIXED_TEXT_H_
