// Atomic output (ulc/io/atomic_file.hpp): a file appears whole or not at all; an abandoned write
// leaves no temporary; the temporaries being written are what remove_pending_temporaries (the
// signal handler's call) removes.
#include <catch2/catch.hpp>
#include <filesystem>
#include <string>

#include "io_test_util.hpp"
#include "ulc/io/atomic_file.hpp"
#include "ulc/io/file_bytes.hpp"

namespace {

/// Files in `dir` whose name holds the temporary marker.
int temporaries_in(const std::filesystem::path& dir) {
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().filename().string().find(ulc::io::kTemporaryMarker) != std::string::npos) ++n;
  return n;
}

std::string text_of(const std::filesystem::path& p) {
  const auto bytes = ulc::io::read_file_bytes(p);
  return std::string(bytes.begin(), bytes.end());
}

}  // namespace

TEST_CASE("atomic file: written whole, replacing the old file, no temporary left", "[io][atomic]") {
  io_test::TempDir dir;
  const auto target = dir / "result.json";
  ulc::io::write_file_text(target, "old\n");
  ulc::io::write_file_text(target, "new\n");
  CHECK(text_of(target) == "new\n");
  CHECK(temporaries_in(dir.path()) == 0);
}

TEST_CASE("atomic file: an abandoned write leaves the old file and no temporary", "[io][atomic]") {
  io_test::TempDir dir;
  const auto target = dir / "cloud.pcd";
  ulc::io::write_file_text(target, "old\n");
  {
    ulc::io::AtomicFile file(target);
    io_test::write_text(file.temporary(), "half a clo");
    CHECK(file.temporary().parent_path() == dir.path());
    CHECK(temporaries_in(dir.path()) == 1);
  }  // no commit: an exception on the way, say
  CHECK(text_of(target) == "old\n");
  CHECK(temporaries_in(dir.path()) == 0);
}

TEST_CASE("atomic file: the pending temporaries are what the signal handler removes",
          "[io][atomic]") {
  io_test::TempDir dir;
  ulc::io::AtomicFile a(dir / "a.json"), b(dir / "b.png");
  io_test::write_text(a.temporary(), "a");
  io_test::write_text(b.temporary(), "b");
  b.commit();
  CHECK(std::filesystem::exists(dir / "b.png"));
  ulc::io::remove_pending_temporaries();  // what the SIGINT handler calls
  CHECK(temporaries_in(dir.path()) == 0);
  CHECK(std::filesystem::exists(dir / "b.png"));  // a committed file stays
  CHECK_FALSE(std::filesystem::exists(dir / "a.json"));
}

TEST_CASE("atomic file: a missing folder or a folder name is an IoError naming the target",
          "[io][atomic]") {
  io_test::TempDir dir;
  const auto missing = dir / "nowhere" / "result.json";
  io_test::require_io_error([&] { ulc::io::write_file_text(missing, "x"); },
                            {missing.string(), "cannot open for writing"});
  io_test::require_io_error([&] { ulc::io::AtomicFile f(dir.path() / ""); }, {"is a folder name"});
}
