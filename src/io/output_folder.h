#pragma once
// The folder the command writes into: never overwritten without --force, and
// every file written under a temporary name and renamed into place, so an
// interrupted run never leaves a half-written file.

#include <functional>
#include <string>

namespace obsgroup::io {

class OutputFolder {
 public:
  /// Creates the folder if needed. Throws UsageError if it already holds
  /// results and `force` is false, or if the path is not a folder.
  OutputFolder(std::string path, bool force);

  /// The checks of the constructor, without creating anything.
  static void check(const std::string& path, bool force);

  /// The full path of a file in the folder.
  std::string path(const std::string& relative) const;

  /// Writes `relative` through `write`, which is given a temporary path in
  /// the same folder to write to; the file then replaces `relative` at once.
  void write(const std::string& relative, const std::function<void(const std::string& temporary)>& write) const;
  void writeText(const std::string& relative, const std::string& content) const;

  /// The files a run writes; their presence means the folder holds results.
  static const char* const kResultFiles[];

 private:
  std::string path_;
};

}  // namespace obsgroup::io
