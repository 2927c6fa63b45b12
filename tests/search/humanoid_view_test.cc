// Estimate::Humanoids() reads the humanoids in place: the detections that passed, in order, the
// same objects as in `detections` (so a pointer to one stays valid with the Estimate), and it is
// not offered on a temporary Estimate.
#include "core/search/humanoid_view.h"

#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "core/search/estimate.h"

namespace hpose {
namespace {

template <typename T, typename = void>
struct HasHumanoids : std::false_type {};
template <typename T>
struct HasHumanoids<T, std::void_t<decltype(std::declval<T>().Humanoids())>> : std::true_type {};

static_assert(HasHumanoids<const Estimate&>::value, "a named Estimate lists its humanoids");
static_assert(HasHumanoids<Estimate&>::value, "a named Estimate lists its humanoids");
static_assert(!HasHumanoids<Estimate>::value, "a temporary Estimate's view would dangle");
static_assert(!HasHumanoids<const Estimate&&>::value, "a temporary Estimate's view would dangle");

Estimate WithHumanoids(const std::vector<bool>& humanoid) {
  Estimate e;
  for (size_t i = 0; i < humanoid.size(); ++i) {
    Detection d;
    d.best.template_name = "t" + std::to_string(i);
    d.is_humanoid = humanoid[i];
    e.detections.push_back(d);
  }
  return e;
}

std::vector<std::string> Names(const HumanoidView& v) {
  std::vector<std::string> out;
  for (const Detection& d : v) out.push_back(d.best.template_name);
  return out;
}

TEST(HumanoidViewTest, ListsThePassedDetectionsInOrderWhereverTheyStand) {
  const Estimate e = WithHumanoids({false, true, false, false, true, true, false});
  const HumanoidView v = e.Humanoids();
  EXPECT_EQ(Names(v), (std::vector<std::string>{"t1", "t4", "t5"}));
  EXPECT_EQ(v.size(), 3u);
  EXPECT_FALSE(v.empty());
  EXPECT_EQ(v.front().best.template_name, "t1");
  auto it = v.begin();
  EXPECT_EQ((it++)->best.template_name, "t1");
  EXPECT_EQ(it->best.template_name, "t4");
}

TEST(HumanoidViewTest, EmptyWhenNothingPassedOrNothingWasDetected) {
  for (const Estimate& e :
       {WithHumanoids({}), WithHumanoids({false}), WithHumanoids({false, false})}) {
    const HumanoidView v = e.Humanoids();
    EXPECT_TRUE(v.empty());
    EXPECT_EQ(v.size(), 0u);
    EXPECT_TRUE(v.begin() == v.end());
    EXPECT_TRUE(static_cast<std::vector<Detection>>(v).empty());
  }
}

TEST(HumanoidViewTest, ReadsTheEstimatesOwnDetectionsAndCopiesOnRequest) {
  Estimate e = WithHumanoids({true, false, true});
  // A pointer taken in a loop stays valid after it: it points into e.detections.
  const Detection* last = nullptr;
  for (const Detection& d : e.Humanoids()) last = &d;
  EXPECT_EQ(last, &e.detections[2]);
  EXPECT_EQ(&e.Humanoids().front(), &e.detections[0]);

  // The view follows the list; a copy keeps what it held.
  const std::vector<Detection> kept = e.Humanoids();
  e.detections[0].is_humanoid = false;
  e.detections[1].is_humanoid = true;
  EXPECT_EQ(Names(e.Humanoids()), (std::vector<std::string>{"t1", "t2"}));
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept[0].best.template_name, "t0");
  EXPECT_EQ(kept[1].best.template_name, "t2");
}

}  // namespace
}  // namespace hpose
