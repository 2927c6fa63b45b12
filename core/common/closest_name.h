#ifndef HPOSE_CORE_COMMON_CLOSEST_NAME_H_
#define HPOSE_CORE_COMMON_CLOSEST_NAME_H_

#include <string>
#include <vector>

namespace hpose {

// The name among `names` that `typed` most likely meant, for "did you mean ...?": the one
// fewest edits away (a letter added, dropped, changed, or two neighbours swapped), when that is
// a slip rather than another word: at most one edit per three letters of the name, at least
// one. Ties go to the name listed first. "" when none is that close, or `typed` is a name.
std::string ClosestName(const std::string& typed, const std::vector<std::string>& names);

// " (did you mean 'NAME'?)" for the closest name (ClosestName), quoted with `prefix` before
// it ("--" for flags); "" when there is none.
std::string DidYouMean(const std::string& typed, const std::vector<std::string>& names,
                       const std::string& prefix = "");

}  // namespace hpose

#endif  // HPOSE_CORE_COMMON_CLOSEST_NAME_H_
