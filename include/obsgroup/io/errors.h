#pragma once
// Errors the command reports to its user, with the exit code they map to.

#include <stdexcept>
#include <string>

namespace obsgroup::io {

/// The command line is wrong or asks for something refused (exit code 2).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An input file is missing, unreadable or malformed (exit code 3). The
/// message names the file, the line (or PCD file) and the field.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// "file:line: message"
inline InputError inputError(const std::string& file, std::size_t line, const std::string& message) {
  return InputError(file + ":" + std::to_string(line) + ": " + message);
}

}  // namespace obsgroup::io
