#include "io/file_io.h"

#include <gtest/gtest.h>

#include <functional>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"

namespace fleetmap::io {
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


std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

TEST(FileIo, ReadRefusesDevicesFifosAndLinkLoopsAndStopsAtTheLimit) {
  const fs::path d = temp_dir("special");
  EXPECT_NE(message_of([] { read_file("/dev/zero", 1024); }).find("/dev/zero: is a character device, expected a regular file"),
            std::string::npos);
  ASSERT_EQ(::mkfifo((d / "fifo").c_str(), 0600), 0);
  // A FIFO would block the reader forever; it is refused without being opened.
  EXPECT_NE(message_of([&] { read_file(d / "fifo"); }).find("is a FIFO (named pipe), expected a regular file"),
            std::string::npos);
  fs::create_symlink("loop", d / "loop");
  EXPECT_NE(message_of([&] { read_file(d / "loop"); }).find("too many levels of symbolic links"), std::string::npos);
  write_file_atomic(d / "big.txt", std::string(5000, 'x'));
  EXPECT_NE(message_of([&] { read_file(d / "big.txt", 4999); }).find("file too large (over the limit of 4999 bytes)"),
            std::string::npos);
  EXPECT_EQ(read_file(d / "big.txt", 5000).size(), 5000u);
}

TEST(FileIo, WritingFollowsALinkAndNeverReplacesADeviceOrTheLink) {
  const fs::path d = temp_dir("links");
  fs::create_symlink("target.txt", d / "link.txt");
  write_file_atomic(d / "link.txt", "through the link");
  EXPECT_TRUE(fs::is_symlink(d / "link.txt"));
  EXPECT_EQ(read_text(d / "target.txt"), "through the link");
  fs::create_symlink("/dev/null", d / "null_link");
  EXPECT_THROW(write_file_atomic(d / "null_link", "x"), InputError);
  EXPECT_THROW(write_file_atomic("/dev/null", "x"), InputError);
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  EXPECT_TRUE(fs::is_symlink(d / "null_link"));
}

TEST(FileIo, AnOutputIsNeverAnInputThroughAnyPathOrLink) {
  const fs::path d = temp_dir("same");
  write_file_atomic(d / "map.pgm", "P5 1 1 255 x");
  fs::create_hard_link(d / "map.pgm", d / "hard.pgm");
  fs::create_symlink("map.pgm", d / "soft.pgm");
  const std::vector<fs::path> inputs = {d / "map.pgm"};
  for (const fs::path& out : {d / "map.pgm", d / "hard.pgm", d / "soft.pgm", d / "sub" / ".." / "map.pgm"}) {
    EXPECT_NE(message_of([&] { check_output_file(out, inputs, "--out"); }).find("fleetmap never overwrites an input"),
              std::string::npos) << out;
  }
  EXPECT_NO_THROW(check_output_file(d / "new.pgm", inputs, "--out"));
  EXPECT_NO_THROW(check_output_file("-", inputs, "--out"));
  EXPECT_NE(message_of([&] { check_output_file("/dev/null", inputs, "--json"); }).find("--json /dev/null: exists and is a character device"),
            std::string::npos);
  EXPECT_NE(message_of([&] { check_output_file(d / "map.pgm" / "x.json", {}, "--json"); }).find("is not a folder"),
            std::string::npos);
}

TEST(OutputFolder, TakesOnlyANewOrEmptyFolderOrOneOfAnEarlierRun) {
  const fs::path d = temp_dir("folder");
  // New: nothing is written until claim().
  OutputFolder fresh(d / "run", "explore", {"a.png", "b.png", "c.png"}, {}, "--out run");
  EXPECT_FALSE(fs::exists(d / "run"));
  fresh.claim();
  EXPECT_TRUE(fs::is_regular_file(d / "run" / OutputFolder::kListName));
  for (const char* n : {"a.png", "b.png", "c.png"}) write_file_atomic(d / "run" / n, n);
  fresh.finish({"a.png", "b.png", "c.png"});
  // A second, smaller run: b.png is replaced, c.png (not written again) removed, a leftover temporary too.
  write_file_atomic(d / "run" / "c.png.tmp.123.0", "half");
  write_file_atomic(d / "run" / (std::string(OutputFolder::kListName) + ".tmp.123.1"), "half a list");
  OutputFolder again(d / "run", "explore", {"a.png", "b.png"}, {}, "--out run");
  again.claim();
  EXPECT_FALSE(fs::exists(d / "run" / "c.png.tmp.123.0"));
  EXPECT_FALSE(fs::exists(d / "run" / (std::string(OutputFolder::kListName) + ".tmp.123.1")));
  write_file_atomic(d / "run" / "a.png", "new a");
  again.finish({"a.png"});
  EXPECT_EQ(read_text(d / "run" / "a.png"), "new a");
  EXPECT_FALSE(fs::exists(d / "run" / "b.png"));
  EXPECT_FALSE(fs::exists(d / "run" / "c.png"));
  EXPECT_NE(read_text(d / "run" / OutputFolder::kListName).find("a.png"), std::string::npos);
  // A file of the user's in it: refused, and nothing is touched.
  write_file_atomic(d / "run" / "notes.txt", "mine");
  EXPECT_NE(message_of([&] { OutputFolder(d / "run", "explore", {"a.png"}, {}, "--out run"); })
                .find("--out run: holds a file that no earlier 'fleetmap explore' run wrote ('notes.txt')"),
            std::string::npos);
  EXPECT_EQ(read_text(d / "run" / "notes.txt"), "mine");
  fs::remove(d / "run" / "notes.txt");
  // Another command's folder, an input inside, a file where the folder should be.
  EXPECT_NE(message_of([&] { OutputFolder(d / "run", "bench", {"a.png"}, {}, "--out run"); })
                .find("holds the outputs of 'fleetmap explore', not of 'fleetmap bench'"),
            std::string::npos);
  EXPECT_NE(message_of([&] { OutputFolder(d / "run", "explore", {"x.png"}, {d / "run" / "a.png"}, "--out run"); })
                .find("holds the input"),
            std::string::npos);
  write_file_atomic(d / "plain", "x");
  EXPECT_NE(message_of([&] { OutputFolder(d / "plain", "explore", {"x.png"}, {}, "--out plain"); })
                .find("--out plain: is a file, expected a folder for the outputs"),
            std::string::npos);
  // A folder of the user's files without a list is never taken, even when the names match.
  write_file_atomic(d / "mine" / "a.png", "user's picture");
  EXPECT_THROW(OutputFolder(d / "mine", "explore", {"a.png"}, {}, "--out mine"), InputError);
  EXPECT_EQ(read_text(d / "mine" / "a.png"), "user's picture");
}

TEST(FileIo, PrintableEscapesControlCharacters) {
  EXPECT_EQ(printable("of\x01ice\nx\ty"), "of\\x01ice\\x0Ax\\x09y");
  EXPECT_EQ(printable("plain/ünïcode.png"), "plain/ünïcode.png");
}

}  // namespace
}  // namespace fleetmap::io
