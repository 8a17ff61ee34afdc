#pragma once
// The folder the command writes into, replaced as a whole: every result is
// written into a hidden staging folder beside it, and commit() swaps the two
// at once (renameat2 RENAME_EXCHANGE). A run that fails or is interrupted
// before commit() leaves the folder exactly as it was: the old results, or
// none, never a mix. Results are never replaced without --force, and a
// folder holding files obsgroup did not write is never replaced at all.

#include <obsgroup/common/interrupt.h>

#include <functional>
#include <string>

namespace obsgroup::io {

class OutputFolder {
 public:
  /// Checks the folder (see check()) and creates the staging folder beside
  /// it. Every write() checks `interrupt` first and throws Interrupted.
  OutputFolder(const std::string& path, bool force, const InterruptFlag* interrupt = nullptr);
  /// Removes the staging folder unless commit() succeeded.
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  /// Throws UsageError if `path` is not a folder, holds results and `force`
  /// is false, or holds anything obsgroup did not write. Creates nothing.
  static void check(const std::string& path, bool force);

  /// The staging path of a file of the results.
  std::string path(const std::string& relative) const;

  /// Writes `relative` through `write`, which is given the path to write to.
  void write(const std::string& relative, const std::function<void(const std::string& path)>& write) const;
  void writeText(const std::string& relative, const std::string& content) const;

  /// Puts the staged results in place of the folder in one step, then
  /// removes the old results.
  void commit();

  /// The entries a run writes; their presence means the folder holds results.
  static const char* const kResultFiles[];

 private:
  std::string target_;
  std::string staging_;
  const InterruptFlag* interrupt_ = nullptr;
  bool committed_ = false;
};

}  // namespace obsgroup::io
