#include "core/io/atomic_file.h"

#include <filesystem>

#include <sys/stat.h>
#include <unistd.h>

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

TEST(AtomicFileTest, MissingDirectoryIsNotFoundNamingThePathAndDirectory) {
  TempDir dir;
  const std::string path = dir.File("no/such/dir/file.txt");
  const Status status = WriteFileAtomically(path, "x");
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().code, ErrorCode::kNotFound);
  EXPECT_NE(status.error().message.find(path), std::string::npos) << status.error().message;
  EXPECT_NE(status.error().message.find("does not exist"), std::string::npos);
  EXPECT_FALSE(CheckOutputPath(path).ok());
  EXPECT_FALSE(CheckOutputPath(dir.path()).ok());  // a directory is not a file.
  EXPECT_TRUE(CheckOutputPath(dir.File("fine.txt")).ok());
}

TEST(AtomicFileTest, DevicesAreWrittenInPlaceAndTheirFailuresReported) {
  // /dev/full accepts opens and fails every write (ENOSPC): the failure must come back, and the
  // device must not be replaced by a renamed temporary file.
  const Status full = WriteFileAtomically("/dev/full", std::string(100000, 'x'));
  ASSERT_FALSE(full.ok());
  struct stat st;
  ASSERT_EQ(::stat("/dev/full", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
  EXPECT_TRUE(WriteFileAtomically("/dev/null", "discarded").ok());
}

TEST(AtomicFileTest, TemporariesOfWritersNoLongerRunningAreRemoved) {
  TempDir dir;
  const std::string path = dir.Write("take.oni", "an earlier take");
  // No process has this id: Linux's process ids stop at pid_max, at most 2^22.
  const std::string dead = std::to_string((1 << 22) + 1);
  const std::string alive = std::to_string(::getppid());  // the process that ran this test.
  const std::string stale = dir.Write(".take.oni.tmp." + dead + ".0", "half a recording");
  const std::string running = dir.Write(".take.oni.tmp." + alive + ".2", "being written");
  const std::string ours = dir.Write(".take.oni.tmp." + std::to_string(::getpid()) + ".7", "x");
  const std::string other_file = dir.Write(".walk.oni.tmp." + dead + ".0", "another output's");
  const std::string not_a_temp = dir.Write(".take.oni.tmp." + dead + ".old", "not our name");
  const std::string not_a_pid = dir.Write(".take.oni.tmp.9999999999.0", "beyond any pid_t");
  EXPECT_EQ(RemoveStaleTemporaries(path), 1);
  EXPECT_FALSE(std::filesystem::exists(stale));
  EXPECT_TRUE(std::filesystem::exists(running));
  EXPECT_TRUE(std::filesystem::exists(ours));
  EXPECT_TRUE(std::filesystem::exists(other_file));
  EXPECT_TRUE(std::filesystem::exists(not_a_temp));
  EXPECT_TRUE(std::filesystem::exists(not_a_pid));
  EXPECT_EQ(Slurp(path), "an earlier take");
  EXPECT_EQ(RemoveStaleTemporaries(path), 0);
  EXPECT_EQ(RemoveStaleTemporaries(dir.File("missing/take.oni")), 0);
}

TEST(AtomicFileTest, ReadFileErrors) {
  TempDir dir;
  Result<std::string> read = ReadFile(dir.File("missing.txt"));
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.error().code, ErrorCode::kNotFound);
  EXPECT_NE(read.error().message.find("missing.txt"), std::string::npos);
  read = ReadFile(dir.path());
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(read.error().message.find("directory"), std::string::npos);
  // A FIFO is refused at once instead of waiting for a writer.
  const std::string fifo = dir.File("fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  read = ReadFile(fifo);
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().message.find("FIFO"), std::string::npos) << read.error().message;
  // An empty file is fine.
  read = ReadFile(dir.Write("empty", ""));
  ASSERT_TRUE(read.ok());
  EXPECT_TRUE(read->empty());
}

}  // namespace
}  // namespace hpose
