#include "output_folder.h"

#include <obsgroup/io/errors.h>

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace obsgroup::io {

namespace fs = std::filesystem;

const char* const OutputFolder::kResultFiles[] = {
    "partition.json", "topology.json",  "topology.dot", "map.png",       "map.svg",       "weights.png",
    "fiedler.png",    "local_maps",     "places.json",  "places.geojson", "places.png",    "places.yaml",
    "occupancy.pgm",  "occupancy.yaml", "map_labelled.pcd", "report.html", nullptr};

namespace {

constexpr const char* kStagingTag = ".obsgroup-staging-";

/// `path` made absolute and without a trailing separator, so that its
/// parent is the folder that holds it ("out/" and "out" are the same).
fs::path normalized(const std::string& path) {
  fs::path p = fs::absolute(path).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  return p;
}

bool isResultEntry(const std::string& name) {
  for (const char* const* known = OutputFolder::kResultFiles; *known; ++known)
    if (name == *known) return true;
  return false;
}

/// What obsgroup writes in local_maps/.
bool isLocalMapEntry(const std::string& name) {
  const fs::path extension = fs::path(name).extension();
  return (name.rfind("group_", 0) == 0 && (extension == ".pcd" || extension == ".png")) || name == "poses.txt";
}

/// The first entry of the folder that obsgroup did not write, or "".
std::string foreignEntry(const fs::path& folder) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (!isResultEntry(name)) return name;
    if (name == "local_maps") {
      if (!entry.is_directory(ec)) return name;
      for (const auto& map : fs::directory_iterator(entry.path(), ec))
        if (!isLocalMapEntry(map.path().filename().string())) return "local_maps/" + map.path().filename().string();
    }
  }
  return "";
}

/// Staging folders of runs that were killed (their process is gone).
void removeAbandonedStaging(const fs::path& target) {
  const std::string prefix = "." + target.filename().string() + kStagingTag;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(target.parent_path(), ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const long pid = std::strtol(name.c_str() + prefix.size(), nullptr, 10);
    if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) fs::remove_all(entry.path(), ec);
  }
}

}  // namespace

void OutputFolder::check(const std::string& path, bool force) {
  const fs::path target = normalized(path);
  std::error_code ec;
  if (!fs::exists(target, ec)) return;
  if (!fs::is_directory(target, ec)) throw UsageError(path + ": exists and is not a folder");
  const std::string foreign = foreignEntry(target);
  if (!foreign.empty())
    throw UsageError(path + ": holds '" + foreign +
                     "', which obsgroup did not write; obsgroup replaces its output folder as a whole, "
                     "so give it a folder of its own");
  if (force) return;
  for (const char* const* name = kResultFiles; *name; ++name)
    if (fs::exists(target / *name, ec))
      throw UsageError(path + ": already holds results (" + *name + "); use --force to replace them");
}

OutputFolder::OutputFolder(const std::string& path, bool force, const InterruptFlag* interrupt)
    : interrupt_(interrupt) {
  check(path, force);
  const fs::path target = normalized(path);
  target_ = target.string();
  std::error_code ec;
  fs::create_directories(target.parent_path(), ec);
  if (ec) throw UsageError(path + ": cannot create the folder that holds it: " + ec.message());
  removeAbandonedStaging(target);
  const fs::path staging =
      target.parent_path() / ("." + target.filename().string() + kStagingTag + std::to_string(::getpid()));
  fs::remove_all(staging, ec);
  fs::create_directories(staging / "local_maps", ec);
  if (ec) throw UsageError(path + ": cannot write beside it (" + staging.string() + "): " + ec.message());
  staging_ = staging.string();
}

OutputFolder::~OutputFolder() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

std::string OutputFolder::path(const std::string& relative) const { return (fs::path(staging_) / relative).string(); }

void OutputFolder::write(const std::string& relative, const std::function<void(const std::string& path)>& write) const {
  throwIfInterrupted(interrupt_);
  write(path(relative));
}

void OutputFolder::writeText(const std::string& relative, const std::string& content) const {
  write(relative, [&content](const std::string& file) {
    std::ofstream out(file, std::ios::binary);
    out << content;
    out.close();
    if (!out) throw std::runtime_error(file + ": cannot write");
  });
}

void OutputFolder::commit() {
  throwIfInterrupted(interrupt_);
  std::error_code ec;
  if (!fs::exists(target_, ec)) {
    if (::rename(staging_.c_str(), target_.c_str()) != 0)
      throw std::runtime_error(target_ + ": cannot move the results in place: " + std::strerror(errno));
    committed_ = true;
    return;
  }
  // The old folder takes the staging name in the same step, then goes.
  if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) != 0) {
    // File systems without RENAME_EXCHANGE: two renames. In between the
    // folder is absent (no results, never a mix) and the old one is kept.
    const std::string old = staging_ + "-old";
    if (::rename(target_.c_str(), old.c_str()) != 0 || ::rename(staging_.c_str(), target_.c_str()) != 0)
      throw std::runtime_error(target_ + ": cannot move the results in place: " + std::strerror(errno));
    fs::remove_all(old, ec);
  }
  committed_ = true;
  fs::remove_all(staging_, ec);  // now the old results
}

}  // namespace obsgroup::io
