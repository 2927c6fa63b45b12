#ifndef HPOSE_TOOLS_FIXED_TEXT_H_
#define HPOSE_TOOLS_FIXED_TEXT_H_

#include <string>

namespace hpose::tools {

// `v` in fixed notation with `decimals` digits after the point ("%.*f"), as the commands print
// figures in their reports.
std::string Fixed(double v, int decimals);

// `v` formatted by `fmt`, a printf format that takes one double ("%.1f s", "x %g m").
std::string FormatNumber(const char* fmt, double v);

// A moving object's closest approach to the robot, `distance_m` away and `in_s` from now, as
// the commands append it to a line: ", passes 313 mm from the robot in 0.45 s", or once that
// moment is past, ", passed 313 mm from the robot 0.45 s ago".
std::string ApproachText(double distance_m, double in_s);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_FIXED_TEXT_H_
