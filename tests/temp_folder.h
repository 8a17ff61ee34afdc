#pragma once
// A test fixture that owns a fresh temporary folder, removed after the test.

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <string>

namespace obsgroup::test {

class TempFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (std::filesystem::temp_directory_path() / "obsgroup_test_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path dir_;
};

}  // namespace obsgroup::test
