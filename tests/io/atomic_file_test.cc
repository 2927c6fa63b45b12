#include "core/io/atomic_file.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "tests/io/temp_dir.h"

namespace hpose {
namespace {

size_t FilesIn(const std::string& dir) {
  size_t n = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    (void)entry;
    ++n;
  }
  return n;
}

TEST(AtomicFileTest, WritesAndReadsBack) {
  TempDir dir;
  const std::string path = dir.File("a.txt");
  std::string contents = "line one\n";
  contents.push_back('\0');  // binary-safe.
  contents += "after a NUL";
  ASSERT_TRUE(WriteFileAtomically(path, contents).ok());
  const Result<std::string> read = ReadFile(path);
  ASSERT_TRUE(read.ok()) << read.error().ToString();
  EXPECT_EQ(*read, contents);
  EXPECT_EQ(FilesIn(dir.path()), 1u) << "no temporary file left behind";
}

TEST(AtomicFileTest, ReplacesAnExistingFile) {
  TempDir dir;
  const std::string path = dir.Write("a.txt", "old contents that are longer");
  ASSERT_TRUE(WriteFileAtomically(path, "new").ok());
  EXPECT_EQ(Slurp(path), "new");
}

TEST(AtomicFileTest, FailedWriterLeavesThePreviousFileIntact) {
  TempDir dir;
  const std::string path = dir.Write("keep.txt", "precious");
  std::string seen_temp;
  const Status status = WriteAtomically(path, [&](const std::string& temp) -> Status {
    seen_temp = temp;
    std::ofstream(temp) << "half-writ";
    return MakeError(ErrorCode::kInternal, "encoder failed");
  });
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().message, "encoder failed");
  EXPECT_EQ(Slurp(path), "precious");
  EXPECT_FALSE(std::filesystem::exists(seen_temp)) << "the temporary file is removed";
  EXPECT_EQ(FilesIn(dir.path()), 1u);
  // The temporary file is a sibling of the target (same file system for rename()).
  EXPECT_EQ(std::filesystem::path(seen_temp).parent_path(), std::filesystem::path(dir.path()));
}

TEST(AtomicFileTest, WriterThatWritesNothingIsAnError) {
  TempDir dir;
  const Status status =
      WriteAtomically(dir.File("x"), [](const std::string&) { return Status::Ok(); });
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().code, ErrorCode::kInternal);
  EXPECT_FALSE(std::filesystem::exists(dir.File("x")));
}

TEST(AtomicFileTest, MissingDirectoryIsInternalErrorNamingThePath) {
  TempDir dir;
  const std::string path = dir.File("no/such/dir/file.txt");
  const Status status = WriteFileAtomically(path, "x");
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().code, ErrorCode::kInternal);
  EXPECT_NE(status.error().message.find(path), std::string::npos) << status.error().message;
}

TEST(AtomicFileTest, ReadFileErrors) {
  TempDir dir;
  Result<std::string> read = ReadFile(dir.File("missing.txt"));
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.error().code, ErrorCode::kNotFound);
  EXPECT_NE(read.error().message.find("missing.txt"), std::string::npos);
  read = ReadFile(dir.path());
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.error().code, ErrorCode::kInternal);
  EXPECT_NE(read.error().message.find("directory"), std::string::npos);
  // An empty file is fine.
  read = ReadFile(dir.Write("empty", ""));
  ASSERT_TRUE(read.ok());
  EXPECT_TRUE(read->empty());
}

}  // namespace
}  // namespace hpose
