#include "core/common/file_names.h"

#include <gtest/gtest.h>

namespace hpose {
namespace {

TEST(FileNamesTest, LowerCaseChangesAsciiLettersOnly) {
  EXPECT_EQ(LowerCase("Depth_001.PNG"), "depth_001.png");
  EXPECT_EQ(LowerCase(""), "");
  EXPECT_EQ(LowerCase("\xc3\x84-9_Z"), "\xc3\x84-9_z");  // bytes of a UTF-8 letter kept.
}

TEST(FileNamesTest, EndsWithComparesTheWholeSuffix) {
  EXPECT_TRUE(EndsWith("run.oni", ".oni"));
  EXPECT_TRUE(EndsWith("run.oni", ""));
  EXPECT_FALSE(EndsWith("run.ONI", ".oni"));  // case-sensitive.
  EXPECT_FALSE(EndsWith("oni", ".oni"));      // shorter than the suffix.
  EXPECT_FALSE(EndsWith("run.onix", ".oni"));
}

TEST(FileNamesTest, LowerExtensionIsTheLastComponentsFromItsDot) {
  EXPECT_EQ(LowerExtension("frames/Depth.TIFF"), ".tiff");
  EXPECT_EQ(LowerExtension("cloud.tar.PCD"), ".pcd");
  EXPECT_EQ(LowerExtension("dir.d/frame"), "");  // a dot in a directory is no extension.
  EXPECT_EQ(LowerExtension("frame"), "");
  EXPECT_EQ(LowerExtension("frame."), ".");
  EXPECT_EQ(LowerExtension(".hidden"), ".hidden");
}

}  // namespace
}  // namespace hpose
