// Calibration table files: processes adding entries to one table at the same
// time keep every entry (the table read under the lock, at each addition),
// and the lock leaves nothing beside the table.
#include "engine/calibration/table_file.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>

#include "engine/output/file_lock.hpp"
#include "tests/run/scratch_dir.hpp"

namespace flocsim::calibration {
namespace {

namespace fs = std::filesystem;

CalibrationEntry entry(double a) {
  CalibrationEntry e;
  e.hydrodynamic_radius = a;
  e.viscosity = 0.1;
  e.input_radius = a - 0.4;
  return e;
}

TEST(TableFile, WritersAtOnceKeepEveryEntry) {
  const fs::path dir = flocsim::testing::fresh_dir("table_file_writers");
  fs::create_directories(dir);
  const std::string table = (dir / "t.json").string();
  // two processes, 20 entries each, interleaved as the scheduler likes
  std::vector<pid_t> children;
  for (int p = 0; p < 2; ++p) {
    const pid_t pid = fork();
    if (pid == 0) {
      for (int k = 0; k < 20; ++k) add_to_table_file(table, entry(2 + p + 2 * k), "test");
      _exit(0);
    }
    children.push_back(pid);
  }
  for (pid_t pid : children) {
    int status = 0;
    waitpid(pid, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  }
  const CalibrationTable t = CalibrationTable::load(table);
  ASSERT_EQ(t.entries().size(), 40u);
  for (int k = 0; k < 40; ++k) EXPECT_EQ(t.entries()[k].hydrodynamic_radius, 2 + k);
  // nothing but the table is left in its folder
  int files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1);
  fs::remove_all(dir);
}

TEST(TableFile, AnAdditionWaitsForTheLocksHolderAndKeepsItsChange) {
  const fs::path dir = flocsim::testing::fresh_dir("table_file_lock");
  fs::create_directories(dir);
  const std::string table = (dir / "t.json").string();
  int locked[2];
  ASSERT_EQ(pipe(locked), 0);
  // another process holds the lock for 0.3 s and writes the table meanwhile
  const pid_t holder = fork();
  if (holder == 0) {
    const output::FileLock held(table);
    char c = 0;
    [[maybe_unused]] auto n = write(locked[1], &c, 1);
    usleep(300000);
    CalibrationTable mine;
    mine.add(entry(2));
    mine.save(table);
    _exit(0);
  }
  char c = 0;
  ASSERT_EQ(read(locked[0], &c, 1), 1);
  EXPECT_FALSE(fs::exists(table));
  add_to_table_file(table, entry(3), "test");  // waits for the holder, then reads its table
  int status = 0;
  waitpid(holder, &status, 0);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  const CalibrationTable t = CalibrationTable::load(table);
  ASSERT_EQ(t.entries().size(), 2u);
  EXPECT_EQ(t.entries()[0].hydrodynamic_radius, 2);
  EXPECT_EQ(t.entries()[1].hydrodynamic_radius, 3);
  EXPECT_FALSE(fs::exists(output::FileLock::lock_file(table)));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace flocsim::calibration
