#include "core/file_io.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "core/error.h"

namespace fleetmap::core {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("fleetmap_file_io_" + name + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(FileIo, ReadErrorsNameThePath) {
  const fs::path d = temp_dir("read");
  try {
    read_file(d / "missing.png");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.png: no such file"), std::string::npos) << e.what();
  }
  try {
    read_file(d);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
}

TEST(FileIo, AtomicWriteReplacesAndLeavesNoTemporaries) {
  const fs::path d = temp_dir("write");
  const fs::path f = d / "sub" / "out.txt";
  write_file_atomic(f, "first");
  write_file_atomic(f, "second version");
  EXPECT_EQ(read_file(f), "second version");
  int files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(d / "sub")) ++files;
  EXPECT_EQ(files, 1);
}

TEST(FileIo, WriteIntoUnwritablePlaceThrows) {
  const fs::path d = temp_dir("blocked");
  write_file_atomic(d / "plainfile", "x");
  // A regular file where a directory is needed.
  EXPECT_THROW(write_file_atomic(d / "plainfile" / "out.txt", "y"), Error);
}

}  // namespace
}  // namespace fleetmap::core
