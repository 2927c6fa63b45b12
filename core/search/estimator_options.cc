// The option names and defaults of the estimator (estimator.h), apart from the estimator itself
// so that a program that only parses options (the `hpose` front end) does not link the search.
#include <string>

#include "core/search/estimator.h"

namespace hpose {

const char* SearchKindName(SearchKind kind) {
  switch (kind) {
    case SearchKind::kPaper:
      return "paper";
    case SearchKind::kExact:
      return "exact";
  }
  return "?";
}

const char* ScoreKindName(ScoreKind kind) {
  switch (kind) {
    case ScoreKind::kPaper:
      return "paper";
    case ScoreKind::kFreeSpace:
      return "free-space";
  }
  return "?";
}

Result<ScoreKind> ParseScoreKind(const std::string& name) {
  if (name == "paper") return ScoreKind::kPaper;
  if (name == "free-space") return ScoreKind::kFreeSpace;
  return MakeError(ErrorCode::kInvalidArgument,
                   "unknown score '" + name + "' (expected 'paper' or 'free-space')");
}

Result<SearchKind> ParseSearchKind(const std::string& name) {
  if (name == "paper") return SearchKind::kPaper;
  if (name == "exact") return SearchKind::kExact;
  return MakeError(ErrorCode::kInvalidArgument,
                   "unknown search '" + name + "' (expected 'paper' or 'exact')");
}

EstimatorOptions DefaultEstimatorOptions() { return EstimatorOptions{}; }

}  // namespace hpose
