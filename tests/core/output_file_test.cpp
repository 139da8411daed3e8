// OutputFile: written under path + ".partial", renamed on commit, removed or
// kept (and named in a warning) when abandoned.
#include "core/output_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "core/error.h"

namespace throng {
namespace {

namespace fs = std::filesystem;

class OutputFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("throng_output_file_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  static void write(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }
  static std::string read(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  fs::path dir_;
};

TEST_F(OutputFileTest, CommitRenamesTheFinishedFileIntoPlace) {
  const std::string path = (dir_ / "a.txt").string();
  write(path, "old");
  {
    OutputFile f(path);
    EXPECT_EQ(f.writing_path(), path + ".partial");
    write(f.writing_path(), "new");
    EXPECT_EQ(read(path), "old");  // readers see the old file until the new one is whole
    f.commit();
    EXPECT_TRUE(f.committed());
    f.commit();  // idempotent
  }
  EXPECT_EQ(read(path), "new");
  EXPECT_FALSE(fs::exists(path + ".partial"));
}

TEST_F(OutputFileTest, AbandonedFilesAreRemovedOrKeptByName) {
  const std::string removed = (dir_ / "r.txt").string(), kept = (dir_ / "k.txt").string();
  {
    OutputFile r(removed);
    OutputFile k(kept, OutputFile::OnFailure::KeepPartial);
    write(r.writing_path(), "half");
    write(k.writing_path(), "half");
  }
  EXPECT_FALSE(fs::exists(removed));
  EXPECT_FALSE(fs::exists(removed + ".partial"));
  EXPECT_FALSE(fs::exists(kept));
  EXPECT_EQ(read(kept + ".partial"), "half");
}

TEST_F(OutputFileTest, AMovedFileIsOwnedOnce) {
  const std::string path = (dir_ / "m.txt").string();
  OutputFile a(path);
  write(a.writing_path(), "x");
  OutputFile b(std::move(a));
  b.commit();
  EXPECT_EQ(read(path), "x");
}

TEST_F(OutputFileTest, ACommitWithNothingWrittenNamesTheFile) {
  const std::string path = (dir_ / "nothing.txt").string();
  OutputFile f(path);
  try {
    f.commit();
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().file, path);
  }
}

}  // namespace
}  // namespace throng
