#include "base/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "base/csv.h"
#include "base/error.h"

namespace daylit {
namespace {

namespace fs = std::filesystem;

class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("daylit_atomic_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  size_t FileCount() const {
    return static_cast<size_t>(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()));
  }
  fs::path dir_;
};

TEST_F(AtomicFileTest, WritesWholeContent) {
  WriteFileAtomically(dir_ / "out.csv", "a,b\n1,2\n");
  EXPECT_EQ(ReadTextFile(dir_ / "out.csv"), "a,b\n1,2\n");
  EXPECT_EQ(FileCount(), 1u);
}

TEST_F(AtomicFileTest, FailedWriterLeavesOldFileAndNoTemporary) {
  WriteFileAtomically(dir_ / "out.csv", "old\n");
  EXPECT_THROW(WriteFileAtomically(dir_ / "out.csv",
                                   [](std::ostream& out) {
                                     out << "half of a ";
                                     throw std::runtime_error("row 7 is bad");
                                   }),
               std::runtime_error);
  EXPECT_EQ(ReadTextFile(dir_ / "out.csv"), "old\n");
  EXPECT_EQ(FileCount(), 1u);
}

TEST_F(AtomicFileTest, UnwritableFolderIsAnInputError) {
  EXPECT_THROW(WriteFileAtomically(dir_ / "no" / "such" / "out.csv", "x"), InputError);
  EXPECT_EQ(FileCount(), 0u);
}

}  // namespace
}  // namespace daylit
