#pragma once
// A fresh folder for one test's files: named after the process and the test, so that tests may
// run in parallel; removed after the test.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace artcal::test_support {

class TempFolder : public ::testing::Test {
 public:
  /// FOLDER/name
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  /// Writes `text` to FOLDER/name (its folders created); the path.
  std::string write(const std::string& name, const std::string& text) const {
    std::filesystem::create_directories((dir_ / name).parent_path());
    std::ofstream(dir_ / name) << text;
    return path(name);
  }

 protected:
  /// `prefix` names the kind of test in the folder's name (artcal-PREFIX-PID-TEST).
  explicit TempFolder(std::string prefix) : prefix_(std::move(prefix)) {}
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("artcal-" + prefix_ + "-" + std::to_string(::getpid()) + "-" + info->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;

 private:
  std::string prefix_;
};

}  // namespace artcal::test_support
