#include "output_folder.h"

#include "errors.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace obsgroup::io {

namespace fs = std::filesystem;

const char* const OutputFolder::kResultFiles[] = {"partition.json", "topology.json", "topology.dot", "map.png",
                                                  "map.svg",        "weights.png",   "fiedler.png",  "local_maps",
                                                  nullptr};

void OutputFolder::check(const std::string& path, bool force) {
  std::error_code ec;
  if (fs::exists(path, ec) && !fs::is_directory(path, ec)) throw UsageError(path + ": exists and is not a folder");
  if (force) return;
  for (const char* const* name = kResultFiles; *name; ++name)
    if (fs::exists(fs::path(path) / *name, ec))
      throw UsageError(path + ": already holds results (" + *name + "); use --force to replace them");
}

OutputFolder::OutputFolder(std::string path, bool force) : path_(std::move(path)) {
  check(path_, force);
  std::error_code ec;
  fs::create_directories(fs::path(path_) / "local_maps", ec);
  if (ec) throw UsageError(path_ + ": cannot create the folder: " + ec.message());
  if (force) {
    // Local maps of an earlier run with more groups must not survive next to the new ones.
    for (const auto& entry : fs::directory_iterator(fs::path(path_) / "local_maps", ec))
      if (entry.path().extension() == ".pcd" && entry.path().filename().string().rfind("group_", 0) == 0)
        fs::remove(entry.path(), ec);
  }
}

std::string OutputFolder::path(const std::string& relative) const { return (fs::path(path_) / relative).string(); }

void OutputFolder::write(const std::string& relative,
                         const std::function<void(const std::string& temporary)>& write) const {
  const fs::path target = fs::path(path_) / relative;
  const fs::path temporary =
      target.parent_path() / ("." + target.filename().string() + ".tmp" + std::to_string(::getpid()));
  try {
    write(temporary.string());
  } catch (...) {
    std::error_code ec;
    fs::remove(temporary, ec);
    throw;
  }
  std::error_code ec;
  fs::rename(temporary, target, ec);  // atomic within one file system
  if (ec) {
    fs::remove(temporary, ec);
    throw std::runtime_error(target.string() + ": cannot write: " + ec.message());
  }
}

void OutputFolder::writeText(const std::string& relative, const std::string& content) const {
  write(relative, [&content](const std::string& temporary) {
    std::ofstream out(temporary, std::ios::binary);
    out << content;
    out.close();
    if (!out) throw std::runtime_error(temporary + ": cannot write");
  });
}

}  // namespace obsgroup::io
