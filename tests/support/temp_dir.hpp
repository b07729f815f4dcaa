#pragma once
// A fresh folder for one test's files, removed with everything in it at the end of the test.

#include <chrono>
#include <filesystem>
#include <random>
#include <string>

namespace evldt::test_support {

class TempDir {
 public:
  TempDir() {
    const auto unique = std::to_string(std::random_device{}()) + "-" +
                        std::to_string(std::chrono::steady_clock::now().time_since_epoch().count());
    path_ = std::filesystem::temp_directory_path() / ("evldt-test-" + unique);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  [[nodiscard]] std::filesystem::path file(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

}  // namespace evldt::test_support
