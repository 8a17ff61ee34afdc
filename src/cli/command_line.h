#pragma once
// The command line of `obsgroup`, parsed into the arguments of a run.

#include "partition_command.h"

#include <optional>
#include <string>

namespace obsgroup::cli {

/// A command line parsed: the arguments of a run, or how it ended.
struct ParsedCommandLine {
  /// Set: run these (their options checked together, the --paper preset applied).
  std::optional<PartitionArgs> args;
  /// Otherwise the exit code: 0 after --help or --version (printed on
  /// stdout), 2 for a usage error.
  int exit_code = 0;
  std::string error;      ///< the usage error, for "obsgroup: error: ..."
  std::string help_hint;  ///< where to read more, for errors of the options' syntax
};

/// Parses `obsgroup COMMAND INPUT -o OUTPUT [options]` (argv[0] is the
/// program). Never throws for what a user typed: errors come back in
/// `error`. The interrupt flag is the caller's to set.
ParsedCommandLine parseCommandLine(int argc, const char* const* argv);

}  // namespace obsgroup::cli
